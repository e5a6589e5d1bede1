#pragma once
// Runs one recursive identification of a log on a thread of its own, as far as it is asked:
// the Recursive panel moves the target with the playhead, the runner processes the samples up
// to it and hands the new rows over in chunks. The steps are core's (prepareRecursiveData,
// startRecursive, the estimator, finishRecursive), the ones the command line runs in one call.
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/recursive/recursive_log.h"

namespace flexarm {

class RecursiveRunner {
 public:
  struct Chunk {
    int run = 0;                                 // the run it belongs to
    std::vector<RecursiveParameter> parameters;  // with the first chunk of a run
    RecursiveTrajectory rows;                    // rows computed since the previous chunk
    double reached = 0.0;   // log time of the last sample processed (before the first: start - T)
    double sampleTime = 0.0, startTime = 0.0, endTime = 0.0;  // of the prepared data
    bool finished = false;  // every sample processed, or stopped (diverged, failed)
    std::shared_ptr<const RecursiveResult> result;  // the summary, with the last chunk
    std::string failure;    // a sentence when the run could not start
    std::string preparation;
  };
  // Called on the runner's thread with every chunk.
  using Sink = std::function<void(Chunk)>;

  RecursiveRunner() = default;
  ~RecursiveRunner();
  RecursiveRunner(const RecursiveRunner&) = delete;
  RecursiveRunner& operator=(const RecursiveRunner&) = delete;

  // Stops a run in progress and starts run `id` on the log (as read) with the model.
  void start(int id, std::shared_ptr<const IdData> log, std::shared_ptr<const ParametricModel> nominal,
             const RecursiveDataOptions& data, const RecursiveOptions& options, Sink sink);
  // Processes the samples whose time is at most t (only ever moves forward).
  void setTarget(double t);
  // Cancels the run in progress: its thread stops within a chunk and sends a last chunk with
  // the summary of what it computed (termination cancelled). Returns at once.
  void cancel();
  // Stops the run and waits for its thread (no last chunk).
  void stop();

 private:
  void work(int id, std::shared_ptr<const IdData> log, std::shared_ptr<const ParametricModel> nominal,
            RecursiveDataOptions data, RecursiveOptions options, Sink sink);

  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  double target_ = -1e300;
  bool stop_ = false;
  bool cancel_ = false;
};

}  // namespace flexarm
