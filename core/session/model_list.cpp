#include "core/session/model_list.h"

#include <stdexcept>
#include <utility>

namespace flexarm {

int ModelList::indexOf(const std::string& name) const {
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<std::string> ModelList::names() const {
  std::vector<std::string> out;
  for (const auto& e : entries_) out.push_back(e.name);
  return out;
}

std::string ModelList::uniqueName(const std::string& base) const {
  if (indexOf(base) < 0) return base;
  for (int k = 2;; ++k) {
    const std::string name = base + " (" + std::to_string(k) + ")";
    if (indexOf(name) < 0) return name;
  }
}

std::string ModelList::resultName(const std::string& base, const Provenance& p) const {
  return uniqueResultName(base, p, names());
}

std::string ModelList::insert(std::size_t index, ModelEntry entry) {
  if (index > entries_.size()) throw std::out_of_range("ModelList::insert: no such position");
  entry.name = uniqueName(entry.name);
  entries_.insert(entries_.begin() + static_cast<std::ptrdiff_t>(index), std::move(entry));
  return entries_[index].name;
}

std::string ModelList::replace(std::size_t index, ModelEntry entry) {
  if (index >= entries_.size()) throw std::out_of_range("ModelList::replace: no such model");
  const int other = indexOf(entry.name);
  if (other >= 0 && static_cast<std::size_t>(other) != index) entry.name = uniqueName(entry.name);
  entries_[index] = std::move(entry);
  return entries_[index].name;
}

void ModelList::remove(std::size_t index) {
  if (index >= entries_.size()) throw std::out_of_range("ModelList::remove: no such model");
  entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(index));
}

std::vector<std::pair<std::size_t, std::string>> ModelList::estimatedOnOtherData(const Provenance& open) const {
  std::vector<std::pair<std::size_t, std::string>> out;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const auto p = entries_[i].dataProvenance();
    if (!p) continue;
    const std::string other = dataMismatch(*p, open);
    if (!other.empty()) out.emplace_back(i, other);
  }
  return out;
}

}  // namespace flexarm
