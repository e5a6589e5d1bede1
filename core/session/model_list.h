#pragma once
// The shared model list and its rules, without Qt: names are unique (a new model of a
// structure is "two-mass", then "two-mass (2)"; an estimate names its data, "three-mass
// estimate 2 (chirp.csv 0.5-12 s)", uniqueResultName), and an estimate made on other data than
// the open ones stays in the list with its values as estimated while every figure of it is of
// the open data (estimatedOnOtherData).
#include <optional>
#include <string>
#include <vector>

#include "core/session/model_entry.h"

namespace flexarm {

class ModelList {
 public:
  const std::vector<ModelEntry>& entries() const { return entries_; }
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  const ModelEntry& operator[](std::size_t i) const { return entries_.at(i); }
  // The index of the entry called name; -1 when none is.
  int indexOf(const std::string& name) const;
  std::vector<std::string> names() const;

  // A name no entry has: base itself, else "base (k)" with the smallest free k >= 2.
  std::string uniqueName(const std::string& base) const;
  // The name of an estimate computed on data p (uniqueResultName, core/session/provenance.h).
  std::string resultName(const std::string& base, const Provenance& p) const;

  // Changes by index (0 <= index <= size() for insert, < size() otherwise; others throw
  // std::out_of_range). An entry named as another one is renamed by uniqueName; the name it
  // got is returned.
  std::string insert(std::size_t index, ModelEntry entry);
  std::string replace(std::size_t index, ModelEntry entry);
  void remove(std::size_t index);
  void clear() { entries_.clear(); }

  // The estimates computed on other data than open, by index, with the sentence saying how
  // the data differ (dataMismatch).
  std::vector<std::pair<std::size_t, std::string>> estimatedOnOtherData(const Provenance& open) const;

 private:
  std::vector<ModelEntry> entries_;
};

}  // namespace flexarm
