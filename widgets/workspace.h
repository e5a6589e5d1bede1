#pragma once
// The data every panel shares: the opened log, the result of preprocessing (what later
// panels use), and the estimation and validation ranges, kept in seconds so they survive
// decimation. Panels observe it through its signals.
#include <QObject>
#include <QString>
#include <memory>
#include <optional>

#include "core/ident/blackbox.h"
#include "core/io/log_io.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/session/model_entry.h"
#include "core/session/provenance.h"
#include "core/signal/id_data.h"
#include "core/signal/preprocess.h"
#include "core/signal/seconds_range.h"

class QUndoStack;

namespace flexarm {


enum class RangeKind { Estimation, Validation };

// A range in seconds (core/signal/seconds_range.h).
using TimeRange = SecondsRange;

// The shared model list holds ModelEntry (core/session/model_entry.h): the one model entry
// the command line, the sessions and every panel use.

// An entry's name as the panels show it.
inline QString nameOf(const ModelEntry& entry) { return QString::fromStdString(entry.name); }

class Workspace : public QObject {
  Q_OBJECT
 public:
  explicit Workspace(QObject* parent = nullptr);

  // Replaces the log (read from path with the given options); ranges stored in its metadata
  // become the workspace's ranges.
  void setLog(IdData data, const QString& path, const LogReadOptions& read = {});
  bool hasLog() const { return raw_ != nullptr; }
  QString logPath() const { return path_; }
  const LogReadOptions& logReadOptions() const { return read_; }
  const IdData* raw() const { return raw_.get(); }
  // The SHA-256 of the log file as opened (set by whoever formed it; empty until then).
  void setLogSha256(const std::string& sum) { sha256_ = sum; }
  const std::string& logSha256() const { return sha256_; }
  // The data a result computed now is computed on: the log's file name and checksum, the
  // preprocessing steps, the ranges, the time (core/session/provenance.h).
  Provenance dataProvenance() const;

  // Results and the data they were computed on: the one record that keeps a result beside
  // its data. A panel records its result under a key ("fit", "diagnosis", "discovery",
  // "recursive") when it shows it, with the provenance it took when the work started (raw:
  // computed on the log as read, so preprocessing does not change its data). When the data
  // change under a record - another log opened, other preprocessing applied or undone - the
  // workspace drops it and emits resultWithdrawn(key) before the data signals: whatever shows
  // that result (its panel, the Arm view's highlight) clears it, and a session or report
  // captured afterwards holds nothing of it.
  // False, recording nothing, when data are not the open data (they changed while the work
  // ran): the result must not be shown.
  bool recordResult(const QString& key, const Provenance& data, bool raw = false);
  // The panel cleared its result itself (a new run started, the user cleared it): no signal.
  void forgetResult(const QString& key);
  // The data of the result recorded under key; nullopt when none is shown.
  std::optional<Provenance> resultData(const QString& key) const;
  bool hasResult(const QString& key) const { return resultData(key).has_value(); }

  // The preprocessed data if preprocessing was applied, otherwise the raw log; null when
  // there is no log or its time stamps are irregular (it must be resampled first).
  const IdData* current() const {
    return processed_ ? processed_.get() : raw_ && raw_->isUniform() ? raw_.get() : nullptr;
  }
  // current() shared: the workspace never changes its data in place, so work off the GUI
  // thread may go on reading them after the workspace moved on to other data.
  std::shared_ptr<const IdData> currentShared() const {
    if (processed_) return processed_;
    if (raw_ && raw_->isUniform()) return raw_;
    return nullptr;
  }
  // What the Log panel draws: current(), or the raw log when it waits for resampling.
  const IdData* shown() const { return processed_ ? processed_.get() : raw_.get(); }
  // shown() shared, for the Log panel's work off the GUI thread.
  std::shared_ptr<const IdData> shownShared() const {
    if (processed_) return processed_;
    return raw_;
  }
  // The raw log has irregular time stamps and no resampling has been applied yet.
  bool needsResampling() const { return raw_ && !raw_->isUniform() && !processed_; }
  bool isPreprocessed() const { return processed_ != nullptr; }
  const PreprocessOptions& preprocessOptions() const { return options_; }
  // Applying and clearing preprocessing, and setting ranges, go through the undo stack.
  void setPreprocessed(IdData data, const PreprocessOptions& options);
  void clearPreprocessed();

  std::optional<TimeRange> range(RangeKind kind) const;
  void setRange(RangeKind kind, TimeRange r);
  void clearRange(RangeKind kind);
  // Samples of current() that the range covers (empty when unset).
  SampleRange samples(RangeKind kind) const;
  // current() with its estimationRange and validationRange set from the workspace ranges.
  IdData currentWithRanges() const;

  // The model list every panel shares. Changes go through the undo stack.
  const std::vector<ModelEntry>& models() const { return models_; }
  int addModel(ModelEntry entry);  // returns its index
  void replaceModel(int index, ModelEntry entry, const QString& what);
  // Model edits, range changes and preprocessing, undoable. Opening a log starts a new
  // history (earlier steps refer to the previous log's data).
  QUndoStack* undoStack() const { return undo_; }
  // Applied by the undo commands and by opening a session; panels use the undoable calls.
  void setPreprocessedDirect(std::shared_ptr<IdData> data, const PreprocessOptions& options);
  void setRangeDirect(RangeKind kind, std::optional<TimeRange> r);
  void setModelDirect(int index, const ModelEntry& entry);
  void insertModelDirect(int index, const ModelEntry& entry);
  void removeModelDirect(int index);

 signals:
  void logChanged();
  void currentChanged();  // the log or its preprocessing changed
  void rangesChanged();
  void modelsChanged(int index);  // index of the changed model, -1 when the list changed
  // The result recorded under key is no longer of the open data (see recordResult).
  void resultWithdrawn(const QString& key);

 private:
  std::shared_ptr<IdData> raw_, processed_;
  PreprocessOptions options_;
  QString path_;
  std::string sha256_;
  LogReadOptions read_;
  std::optional<TimeRange> estimation_, validation_;
  std::vector<ModelEntry> models_;
  QUndoStack* undo_;
  struct ResultRecord {
    QString key;
    Provenance data;
    bool raw = false;
  };
  std::vector<ResultRecord> results_;
  // Drops the records whose data the open data no longer are (all of them: a new log).
  void withdrawResults(bool all);
};

const char* toString(RangeKind kind);

}  // namespace flexarm
