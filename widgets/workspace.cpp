#include "widgets/workspace.h"

#include <QFileInfo>
#include <QStringList>

#include <QUndoCommand>
#include <QUndoStack>
#include <algorithm>

#include "core/io/ranges.h"

namespace flexarm {

const char* toString(RangeKind kind) {
  return kind == RangeKind::Estimation ? "estimation" : "validation";
}

namespace {

class ReplaceModelCommand : public QUndoCommand {
 public:
  ReplaceModelCommand(Workspace* w, int index, ModelEntry before, ModelEntry after, const QString& text)
      : QUndoCommand(text), w_(w), index_(index), before_(std::move(before)), after_(std::move(after)) {}
  void redo() override { w_->setModelDirect(index_, after_); }
  void undo() override { w_->setModelDirect(index_, before_); }

 private:
  Workspace* w_;
  int index_;
  ModelEntry before_, after_;
};

class AddModelCommand : public QUndoCommand {
 public:
  AddModelCommand(Workspace* w, int index, ModelEntry entry)
      : QUndoCommand(QObject::tr("add model %1").arg(nameOf(entry))), w_(w), index_(index), entry_(std::move(entry)) {}
  void redo() override { w_->insertModelDirect(index_, entry_); }
  void undo() override { w_->removeModelDirect(index_); }

 private:
  Workspace* w_;
  int index_;
  ModelEntry entry_;
};

class RangeCommand : public QUndoCommand {
 public:
  RangeCommand(Workspace* w, RangeKind kind, std::optional<TimeRange> after)
      : QUndoCommand(after ? QObject::tr("set %1 range").arg(toString(kind))
                           : QObject::tr("clear %1 range").arg(toString(kind))),
        w_(w), kind_(kind), before_(w->range(kind)), after_(after) {}
  void redo() override { w_->setRangeDirect(kind_, after_); }
  void undo() override { w_->setRangeDirect(kind_, before_); }

 private:
  Workspace* w_;
  RangeKind kind_;
  std::optional<TimeRange> before_, after_;
};

class PreprocessCommand : public QUndoCommand {
 public:
  PreprocessCommand(Workspace* w, std::shared_ptr<IdData> before, PreprocessOptions beforeOptions,
                    std::shared_ptr<IdData> after, PreprocessOptions afterOptions)
      : QUndoCommand(after ? QObject::tr("apply preprocessing") : QObject::tr("undo preprocessing")),
        w_(w), before_(std::move(before)), after_(std::move(after)),
        beforeOptions_(beforeOptions), afterOptions_(afterOptions) {}
  void redo() override { w_->setPreprocessedDirect(after_, afterOptions_); }
  void undo() override { w_->setPreprocessedDirect(before_, beforeOptions_); }

 private:
  Workspace* w_;
  std::shared_ptr<IdData> before_, after_;
  PreprocessOptions beforeOptions_, afterOptions_;
};

}  // namespace

Workspace::Workspace(QObject* parent) : QObject(parent), undo_(new QUndoStack(this)) {}

int Workspace::addModel(ModelEntry entry) {
  const int index = static_cast<int>(models_.size());
  undo_->push(new AddModelCommand(this, index, std::move(entry)));
  return index;
}

void Workspace::replaceModel(int index, ModelEntry entry, const QString& what) {
  if (index < 0 || index >= static_cast<int>(models_.size())) return;
  undo_->push(new ReplaceModelCommand(this, index, models_[static_cast<std::size_t>(index)],
                                      std::move(entry), what));
}

void Workspace::setModelDirect(int index, const ModelEntry& entry) {
  models_[static_cast<std::size_t>(index)] = entry;
  emit modelsChanged(index);
}

void Workspace::insertModelDirect(int index, const ModelEntry& entry) {
  models_.insert(models_.begin() + index, entry);
  emit modelsChanged(-1);
}

void Workspace::removeModelDirect(int index) {
  models_.erase(models_.begin() + index);
  emit modelsChanged(-1);
}

void Workspace::setLog(IdData data, const QString& path, const LogReadOptions& read) {
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
  sha256_.clear();
  read_ = read;
  undo_->clear();
  withdrawResults(true);  // a log opened is a new analysis, even of the same file
  emit logChanged();
  emit currentChanged();
  emit rangesChanged();
}

Provenance Workspace::dataProvenance() const {
  Provenance p;
  p.log = QFileInfo(path_).fileName().toStdString();
  p.sha256 = sha256_;
  p.reading = describeMapping(read_.mapping);
  if (processed_) p.preprocessing = describePreprocessing(options_);
  p.estimation = estimation_;
  p.validation = validation_;
  p.when = utcNow();
  return p;
}

bool Workspace::recordResult(const QString& key, const Provenance& data, bool raw) {
  forgetResult(key);
  ResultRecord r{key, data, raw};
  if (raw) r.data.preprocessing.clear();
  Provenance open = dataProvenance();
  if (raw) open.preprocessing.clear();
  if (!raw_ || !sameData(r.data, open)) return false;
  results_.push_back(std::move(r));
  return true;
}

void Workspace::forgetResult(const QString& key) {
  results_.erase(std::remove_if(results_.begin(), results_.end(),
                                [&](const ResultRecord& r) { return r.key == key; }),
                 results_.end());
}

std::optional<Provenance> Workspace::resultData(const QString& key) const {
  for (const auto& r : results_)
    if (r.key == key) return r.data;
  return std::nullopt;
}

void Workspace::withdrawResults(bool all) {
  const std::vector<std::string> now = processed_ ? describePreprocessing(options_) : std::vector<std::string>{};
  QStringList withdrawn;
  for (auto it = results_.begin(); it != results_.end();) {
    // A result of the log as read keeps its data whatever the preprocessing.
    if (all || (!it->raw && it->data.preprocessing != now)) {
      withdrawn << it->key;
      it = results_.erase(it);
    } else {
      ++it;
    }
  }
  for (const QString& key : withdrawn) emit resultWithdrawn(key);
}

void Workspace::setPreprocessed(IdData data, const PreprocessOptions& options) {
  undo_->push(new PreprocessCommand(this, processed_, options_,
                                    std::make_shared<IdData>(std::move(data)), options));
}

void Workspace::clearPreprocessed() {
  if (!processed_) return;
  undo_->push(new PreprocessCommand(this, processed_, options_, nullptr, PreprocessOptions{}));
}

void Workspace::setPreprocessedDirect(std::shared_ptr<IdData> data, const PreprocessOptions& options) {
  processed_ = std::move(data);
  options_ = processed_ ? options : PreprocessOptions{};
  withdrawResults(false);
  emit currentChanged();
  emit rangesChanged();  // sample counts change with the rate
}

std::optional<TimeRange> Workspace::range(RangeKind kind) const {
  return kind == RangeKind::Estimation ? estimation_ : validation_;
}

void Workspace::setRange(RangeKind kind, TimeRange r) {
  if (r.end < r.start) std::swap(r.start, r.end);
  undo_->push(new RangeCommand(this, kind, r));
}

void Workspace::clearRange(RangeKind kind) {
  if (!range(kind)) return;
  undo_->push(new RangeCommand(this, kind, std::nullopt));
}

void Workspace::setRangeDirect(RangeKind kind, std::optional<TimeRange> r) {
  (kind == RangeKind::Estimation ? estimation_ : validation_) = r;
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
