#pragma once
// The decision structure of the seed's Sections 7.4.2 and 7.5.2: rows are the modes (no fault
// NF and one fault F_i per monitored parameter), columns the test quantities. A 0 says the
// quantity is not affected by that mode, an X that it may be. A quantity above its threshold
// rejects every mode with a 0 in its column; the diagnosis statement S is the set of modes
// left. With one fault at a time, S = {F_i} isolates the fault; NF in S means no fault is
// detected.
//
// The seed's table for the hypothesis tests (7.20)/(7.21), columns T_NF, T_kT, T_Ja^-1, T_fm:
//   F_kT  X 0 X X      a fault in k_T shows as the pattern 1011 -> S = {F_kT}
//   F_Ja  X X 0 X                        J_a^-1:          1101 -> S = {F_Ja}
//   F_fm  X X X 0                        f_m:             1110 -> S = {F_fm}
//   NF    0 X X X      T_NF below 1 keeps NF in S:      0XXX -> NF in S
// The parameter tests (classical, robust, CUSUM) have one column per parameter, affected only
// by that parameter's fault: an alarm on theta_i alone gives S = {F_i}; alarms on two
// parameters at once reject every mode (S empty: not one single fault).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace flexarm {

// A set of modes as bits: bit 0 NF, bit i the fault of monitored parameter i - 1.
using ModeSet = std::uint32_t;

struct DecisionColumn {
  std::string name;  // "T_NF", "T_k_T", "k_T", ...
  ModeSet zeros = 0; // the modes this quantity is not affected by (the 0s of its column)
};

class DecisionStructure {
 public:
  // modes: the fault names (the monitored parameters' model names, e.g. k_T, J_a, f_m); the
  // mode "none" (NF) is added in front.
  DecisionStructure(std::vector<std::string> faults, std::vector<DecisionColumn> columns);
  // Section 7.5.2's table: columns T_NF (0 only for NF) and T_i (0 only for F_i).
  static DecisionStructure hypothesis(const std::vector<std::string>& faults);
  // One column per parameter, 0 for NF and for every other parameter's fault.
  static DecisionStructure parameters(const std::vector<std::string>& faults);

  std::size_t modeCount() const { return faults_.size() + 1; }
  ModeSet allModes() const { return (ModeSet{1} << modeCount()) - 1; }
  const std::vector<std::string>& faults() const { return faults_; }
  const std::vector<DecisionColumn>& columns() const { return columns_; }
  // "none" for mode 0, else the fault's name.
  std::string modeName(std::size_t mode) const;
  // The mark of row `mode`, column `column`: '0' or 'X'.
  char mark(std::size_t mode, std::size_t column) const;

  // S for the columns that fired (one flag per column).
  ModeSet diagnose(const std::vector<bool>& fired) const;

 private:
  std::vector<std::string> faults_;
  std::vector<DecisionColumn> columns_;
};

// "1011": one digit per column, 1 where it fired.
std::string patternString(const std::vector<bool>& fired);
// "{F_k_T}", "{NF, F_f_m}", "{}" as the seed writes S.
std::string modeSetString(ModeSet s, const std::vector<std::string>& faults);
// The fault S isolates (index into faults) when S holds exactly one fault and not NF.
std::optional<std::size_t> isolatedFault(ModeSet s);

// Follows S over time and reaches a verdict: the first isolated fault (S = {F_i}) that held for
// confirmS seconds, at the time it was confirmed; detection: the first time NF left S and
// stayed out for confirmS. Both are latched: once reached they stay.
class VerdictTracker {
 public:
  explicit VerdictTracker(double confirmS = 0.0) : confirm_(confirmS) {}
  void update(double time, ModeSet s);
  std::optional<std::size_t> verdict() const { return verdict_; }  // index into faults
  std::optional<double> verdictTime() const { return verdictTime_; }
  std::optional<double> detectionTime() const { return detectionTime_; }

 private:
  double confirm_;
  std::optional<std::size_t> verdict_, candidate_;
  std::optional<double> verdictTime_, detectionTime_, candidateSince_, detectedSince_;
};

}  // namespace flexarm
