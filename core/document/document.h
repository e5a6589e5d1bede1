#pragma once
// The analysis a window shows, without Qt (as ParaView's proxies hold the state and Qt only
// shows it): the opened log, the result of preprocessing (what later steps use), the
// estimation and validation ranges in seconds (so they survive decimation), the model list,
// and the record of which result was computed on which data. The widgets' Workspace wraps one
// and adds only signals and undo; the command line and the sessions can hold one the same way.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/compare/compare.h"
#include "core/session/model_list.h"
#include "core/io/log_io.h"
#include "core/session/provenance.h"
#include "core/signal/id_data.h"
#include "core/signal/preprocess.h"
#include "core/signal/seconds_range.h"

namespace flexarm {

class Document {
 public:
  // Replaces the log (read from path with the given options): ranges stored in its metadata
  // become the document's, preprocessing is dropped and every recorded result withdrawn (a
  // log opened is a new analysis, even of the same file). Returns the withdrawn results' keys.
  std::vector<std::string> setLog(IdData data, const std::string& path, const LogReadOptions& read = {});
  bool hasLog() const { return raw_ != nullptr; }
  const std::string& logPath() const { return path_; }
  const LogReadOptions& logReadOptions() const { return read_; }
  const IdData* raw() const { return raw_.get(); }
  // The SHA-256 of the log file as opened (set by whoever read it; empty until then).
  void setLogSha256(const std::string& sum) { sha256_ = sum; }
  const std::string& logSha256() const { return sha256_; }
  // The data a result computed now is computed on: the log's file name and checksum, how it
  // was read, the preprocessing steps, the ranges, the time.
  Provenance dataProvenance() const;

  // The preprocessed data if preprocessing was applied, otherwise the raw log; null when there
  // is no log or its time stamps are irregular (it must be resampled first).
  const IdData* current() const { return currentShared().get(); }
  // current() shared: the document never changes its data in place, so work off the GUI
  // thread may go on reading them after the document moved on to other data.
  std::shared_ptr<const IdData> currentShared() const;
  // What a log view draws: current(), or the raw log when it waits for resampling.
  const IdData* shown() const { return processed_ ? processed_.get() : raw_.get(); }
  bool needsResampling() const { return raw_ && !raw_->isUniform() && !processed_; }
  bool isPreprocessed() const { return processed_ != nullptr; }
  const PreprocessOptions& preprocessOptions() const { return options_; }
  std::shared_ptr<IdData> preprocessedShared() const { return processed_; }
  // Applies (data set) or clears (null) preprocessing; returns the keys of the results
  // withdrawn because their data are no longer the open data.
  std::vector<std::string> setPreprocessed(std::shared_ptr<IdData> data, const PreprocessOptions& options);

  std::optional<SecondsRange> range(DataRange kind) const;
  void setRange(DataRange kind, std::optional<SecondsRange> r);
  // Samples of current() that the range covers (empty when unset).
  SampleRange samples(DataRange kind) const;
  // current() with its estimationRange and validationRange set from the document's ranges.
  IdData currentWithRanges() const;
  // The current data, ranges and file name as the evaluations take them (core/compare).
  EvaluationData evaluationData() const;

  // The shared model list.
  const ModelList& models() const { return models_; }
  ModelList& models() { return models_; }

  // Results and the data they were computed on: the one record that keeps a result beside
  // its data. A front end records its result under a key ("fit", "diagnosis", ...) with the
  // provenance it took when the work started (raw: computed on the log as read, so
  // preprocessing does not change its data). False, recording nothing, when those are not
  // the open data (they changed while the work ran): the result must not be shown.
  bool recordResult(const std::string& key, const Provenance& data, bool raw = false);
  void forgetResult(const std::string& key);
  std::optional<Provenance> resultData(const std::string& key) const;

 private:
  std::shared_ptr<IdData> raw_, processed_;
  PreprocessOptions options_;
  std::string path_, sha256_;
  LogReadOptions read_;
  std::optional<SecondsRange> estimation_, validation_;
  ModelList models_;
  struct ResultRecord {
    std::string key;
    Provenance data;
    bool raw = false;
  };
  std::vector<ResultRecord> results_;
  // Drops the records whose data the open data no longer are (all of them: a new log).
  std::vector<std::string> withdrawResults(bool all);
};

}  // namespace flexarm
