#include "core/document/document.h"

#include <algorithm>
#include <filesystem>

#include "core/io/ranges.h"
#include "core/session/session.h"

namespace flexarm {

std::vector<std::string> Document::setLog(IdData data, const std::string& path, const LogReadOptions& read) {
  std::string ignored;
  applyStoredRanges(data, &ignored);
  auto toTime = [&](const std::optional<SampleRange>& r) -> std::optional<SecondsRange> {
    if (!r || r->empty()) return std::nullopt;
    return SecondsRange{data.timeAt(r->begin), data.timeAt(r->end - 1)};
  };
  estimation_ = toTime(data.estimationRange);
  validation_ = toTime(data.validationRange);
  raw_ = std::make_shared<IdData>(std::move(data));
  processed_.reset();
  options_ = PreprocessOptions{};
  path_ = path;
  sha256_.clear();
  read_ = read;
  return withdrawResults(true);
}

Provenance Document::dataProvenance() const {
  Provenance p;
  p.log = std::filesystem::path(path_).filename().string();
  p.sha256 = sha256_;
  p.reading = describeMapping(read_.mapping);
  if (processed_) p.preprocessing = describePreprocessing(options_);
  p.estimation = estimation_;
  p.validation = validation_;
  p.when = utcNow();
  return p;
}

std::shared_ptr<const IdData> Document::currentShared() const {
  if (processed_) return processed_;
  if (raw_ && raw_->isUniform()) return raw_;
  return nullptr;
}

std::vector<std::string> Document::setPreprocessed(std::shared_ptr<IdData> data, const PreprocessOptions& options) {
  processed_ = std::move(data);
  options_ = processed_ ? options : PreprocessOptions{};
  return withdrawResults(false);
}

std::optional<SecondsRange> Document::range(DataRange kind) const {
  return kind == DataRange::Estimation ? estimation_ : validation_;
}

void Document::setRange(DataRange kind, std::optional<SecondsRange> r) {
  if (r && r->end < r->start) std::swap(r->start, r->end);
  (kind == DataRange::Estimation ? estimation_ : validation_) = r;
}

SampleRange Document::samples(DataRange kind) const {
  const IdData* d = current();
  const auto r = range(kind);
  if (!d || !r) return {};
  return d->rangeForTimes(r->start, r->end);
}

IdData Document::currentWithRanges() const {
  IdData d = current() ? *current() : IdData{};
  auto set = [&](DataRange k, std::optional<SampleRange>& out) {
    const SampleRange s = samples(k);
    out = s.empty() ? std::nullopt : std::optional<SampleRange>(s);
  };
  set(DataRange::Estimation, d.estimationRange);
  set(DataRange::Validation, d.validationRange);
  return d;
}

EvaluationData Document::evaluationData() const {
  return {currentShared(), estimation_, validation_, std::filesystem::path(path_).filename().string()};
}

bool Document::recordResult(const std::string& key, const Provenance& data, bool raw) {
  forgetResult(key);
  ResultRecord r{key, data, raw};
  if (raw) r.data.preprocessing.clear();
  Provenance open = dataProvenance();
  if (raw) open.preprocessing.clear();
  if (!raw_ || !sameData(r.data, open)) return false;
  results_.push_back(std::move(r));
  return true;
}

void Document::forgetResult(const std::string& key) {
  results_.erase(std::remove_if(results_.begin(), results_.end(), [&](const ResultRecord& r) { return r.key == key; }),
                 results_.end());
}

std::optional<Provenance> Document::resultData(const std::string& key) const {
  for (const auto& r : results_)
    if (r.key == key) return r.data;
  return std::nullopt;
}

std::vector<std::string> Document::withdrawResults(bool all) {
  const std::vector<std::string> now = processed_ ? describePreprocessing(options_) : std::vector<std::string>{};
  std::vector<std::string> withdrawn;
  for (auto it = results_.begin(); it != results_.end();) {
    // A result of the log as read keeps its data whatever the preprocessing.
    if (all || (!it->raw && it->data.preprocessing != now)) {
      withdrawn.push_back(it->key);
      it = results_.erase(it);
    } else {
      ++it;
    }
  }
  return withdrawn;
}

}  // namespace flexarm
