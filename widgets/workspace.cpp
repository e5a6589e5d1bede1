#include "widgets/workspace.h"

#include <algorithm>

#include "core/io/ranges.h"

namespace flexarm {

const char* toString(RangeKind kind) {
  return kind == RangeKind::Estimation ? "estimation" : "validation";
}

Workspace::Workspace(QObject* parent) : QObject(parent) {}

void Workspace::setLog(IdData data, const QString& path) {
  std::string ignored;
  applyStoredRanges(data, &ignored);
  estimation_.reset();
  validation_.reset();
  auto toTime = [&](const std::optional<SampleRange>& r) -> std::optional<TimeRange> {
    if (!r || r->empty()) return std::nullopt;
    return TimeRange{data.timeAt(r->begin), data.timeAt(r->end - 1)};
  };
  estimation_ = toTime(data.estimationRange);
  validation_ = toTime(data.validationRange);
  raw_ = std::make_shared<IdData>(std::move(data));
  processed_.reset();
  options_ = PreprocessOptions{};
  path_ = path;
  emit logChanged();
  emit currentChanged();
  emit rangesChanged();
}

void Workspace::setPreprocessed(IdData data, const PreprocessOptions& options) {
  processed_ = std::make_shared<IdData>(std::move(data));
  options_ = options;
  emit currentChanged();
  emit rangesChanged();  // sample counts change with the rate
}

void Workspace::clearPreprocessed() {
  if (!processed_) return;
  processed_.reset();
  options_ = PreprocessOptions{};
  emit currentChanged();
  emit rangesChanged();
}

std::optional<TimeRange> Workspace::range(RangeKind kind) const {
  return kind == RangeKind::Estimation ? estimation_ : validation_;
}

void Workspace::setRange(RangeKind kind, TimeRange r) {
  if (r.end < r.start) std::swap(r.start, r.end);
  (kind == RangeKind::Estimation ? estimation_ : validation_) = r;
  emit rangesChanged();
}

void Workspace::clearRange(RangeKind kind) {
  (kind == RangeKind::Estimation ? estimation_ : validation_).reset();
  emit rangesChanged();
}

SampleRange Workspace::samples(RangeKind kind) const {
  const IdData* d = current();
  auto r = range(kind);
  if (!d || !r) return {};
  return d->rangeForTimes(r->start, r->end);
}

IdData Workspace::currentWithRanges() const {
  IdData d = current() ? *current() : IdData{};
  auto set = [&](RangeKind k, std::optional<SampleRange>& out) {
    SampleRange s = samples(k);
    out = s.empty() ? std::nullopt : std::optional<SampleRange>(s);
  };
  set(RangeKind::Estimation, d.estimationRange);
  set(RangeKind::Validation, d.validationRange);
  return d;
}

}  // namespace flexarm
