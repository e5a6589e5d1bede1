#include "core/diagnosis/decision.h"

#include <stdexcept>
#include <utility>

namespace flexarm {

namespace {
constexpr ModeSet bit(std::size_t mode) { return ModeSet{1} << mode; }
}  // namespace

DecisionStructure::DecisionStructure(std::vector<std::string> faults,
                                     std::vector<DecisionColumn> columns)
    : faults_(std::move(faults)), columns_(std::move(columns)) {
  if (faults_.empty() || faults_.size() > 30)
    throw std::invalid_argument("a decision structure needs 1 to 30 faults");
  for (const auto& c : columns_)
    if (c.zeros & ~allModes())
      throw std::invalid_argument("decision column " + c.name + " names a mode that does not exist");
}

DecisionStructure DecisionStructure::hypothesis(const std::vector<std::string>& faults) {
  std::vector<DecisionColumn> columns{{"T_NF", bit(0)}};
  for (std::size_t i = 0; i < faults.size(); ++i) columns.push_back({"T_" + faults[i], bit(i + 1)});
  return DecisionStructure(faults, std::move(columns));
}

DecisionStructure DecisionStructure::parameters(const std::vector<std::string>& faults) {
  std::vector<DecisionColumn> columns;
  const ModeSet all = (ModeSet{1} << (faults.size() + 1)) - 1;
  for (std::size_t i = 0; i < faults.size(); ++i) columns.push_back({faults[i], all & ~bit(i + 1)});
  return DecisionStructure(faults, std::move(columns));
}

std::string DecisionStructure::modeName(std::size_t mode) const {
  return mode == 0 ? "none" : faults_.at(mode - 1);
}

char DecisionStructure::mark(std::size_t mode, std::size_t column) const {
  return (columns_.at(column).zeros & bit(mode)) ? '0' : 'X';
}

ModeSet DecisionStructure::diagnose(const std::vector<bool>& fired) const {
  if (fired.size() != columns_.size())
    throw std::invalid_argument("decision structure: one flag per column expected");
  ModeSet s = allModes();
  for (std::size_t j = 0; j < fired.size(); ++j)
    if (fired[j]) s &= ~columns_[j].zeros;
  return s;
}

std::string patternString(const std::vector<bool>& fired) {
  std::string p;
  for (bool f : fired) p += f ? '1' : '0';
  return p;
}

std::string modeSetString(ModeSet s, const std::vector<std::string>& faults) {
  std::string out = "{";
  for (std::size_t m = 0; m <= faults.size(); ++m) {
    if (!(s & bit(m))) continue;
    if (out.size() > 1) out += ", ";
    out += m == 0 ? "NF" : "F_" + faults[m - 1];
  }
  return out + "}";
}

std::optional<std::size_t> isolatedFault(ModeSet s) {
  if (s == 0 || (s & 1u) || (s & (s - 1)) != 0) return std::nullopt;
  std::size_t m = 0;
  while (!(s & bit(m))) ++m;
  return m - 1;
}

void VerdictTracker::update(double time, ModeSet s) {
  const bool detected = !(s & 1u);
  if (!detected) detectedSince_.reset();
  else if (!detectedSince_) detectedSince_ = time;
  if (detected && !detectionTime_ && time - *detectedSince_ >= confirm_ - 1e-12)
    detectionTime_ = time;

  const auto fault = isolatedFault(s);
  if (fault != candidate_) {
    candidate_ = fault;
    candidateSince_ = fault ? std::optional<double>(time) : std::nullopt;
  }
  if (candidate_ && !verdict_ && time - *candidateSince_ >= confirm_ - 1e-12) {
    verdict_ = candidate_;
    verdictTime_ = time;
  }
}

}  // namespace flexarm
