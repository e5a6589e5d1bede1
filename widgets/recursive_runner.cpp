#include "widgets/recursive_runner.h"

#include <chrono>

namespace flexarm {

namespace {
// A chunk goes out at least this often while the runner catches up with a far target, so
// the plots fill in as it computes.
constexpr auto kChunkInterval = std::chrono::milliseconds(15);
}  // namespace

RecursiveRunner::~RecursiveRunner() { stop(); }

void RecursiveRunner::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void RecursiveRunner::cancel() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancel_ = true;
  }
  wake_.notify_all();
}

void RecursiveRunner::start(int id, std::shared_ptr<const IdData> log,
                            std::shared_ptr<const ParametricModel> nominal,
                            const RecursiveDataOptions& data, const RecursiveOptions& options,
                            Sink sink) {
  stop();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = false;
    cancel_ = false;
    target_ = -1e300;
  }
  thread_ = std::thread(&RecursiveRunner::work, this, id, std::move(log), std::move(nominal), data,
                        options, std::move(sink));
}

void RecursiveRunner::setTarget(double t) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (t <= target_) return;
    target_ = t;
  }
  wake_.notify_all();
}

void RecursiveRunner::work(int id, std::shared_ptr<const IdData> log,
                           std::shared_ptr<const ParametricModel> nominal, RecursiveDataOptions data,
                           RecursiveOptions options, Sink sink) {
  Chunk first;
  first.run = id;
  auto fail = [&](const std::string& why) {
    first.failure = why;
    first.finished = true;
    sink(std::move(first));
  };
  PreparedData prepared;
  std::optional<RecursiveStart> start;
  try {
    prepared = prepareRecursiveData(*log, data);
    first.preparation = prepared.note();
    if (!prepared.ok()) return fail(prepared.message);
    start.emplace(startRecursive(*nominal, prepared.estimationInput(), prepared.estimationOutput(),
                                 prepared.sampleTime, options,
                                 prepared.timeAt(prepared.estimation.begin)));
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  if (!start->estimator) return fail(start->failed.message);
  RecursiveEstimator& est = *start->estimator;
  const Eigen::VectorXd u = prepared.estimationInput(), y = prepared.estimationOutput();
  const auto n = static_cast<std::size_t>(u.size());
  const double T = prepared.sampleTime, t0 = prepared.timeAt(prepared.estimation.begin);
  first.parameters = est.parameters();
  first.sampleTime = T;
  first.startTime = t0;
  first.endTime = t0 + static_cast<double>(n - 1) * T;
  first.reached = t0 - T;
  sink(std::move(first));

  RecursiveTrajectory all;
  all.reserve(n, est.parameters().size());
  std::size_t k = 0;
  bool stopped = false, cancelled = false;
  auto cancelRequested = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    return cancel_;
  };
  while (k < n && !stopped && !cancelled) {
    double target = 0.0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || cancel_ || target_ >= t0 + static_cast<double>(k) * T; });
      if (stop_) return;
      cancelled = cancel_;
      target = target_;
    }
    Chunk chunk;
    chunk.run = id;
    const auto since = std::chrono::steady_clock::now();
    while (!cancelled && k < n && t0 + static_cast<double>(k) * T <= target) {
      const RecursiveStep& s = est.update(u[static_cast<Eigen::Index>(k)], y[static_cast<Eigen::Index>(k)]);
      if (!s.ok) {
        stopped = true;
        break;
      }
      chunk.rows.append(s);
      all.append(s);
      ++k;
      if ((k & 255) == 0 && std::chrono::steady_clock::now() - since > kChunkInterval) break;
      if ((k & 63) == 0) cancelled = cancelRequested();
    }
    chunk.reached = t0 + (static_cast<double>(k) - 1.0) * T;
    chunk.finished = k == n || stopped || cancelled;
    if (chunk.finished) {
      RecursiveResult done = finishRecursive(est, all, n, cancelled, start->Q);
      appendRateNote(done, prepared.decimation);
      chunk.result = std::make_shared<const RecursiveResult>(std::move(done));
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) return;
    }
    sink(std::move(chunk));
  }
}

}  // namespace flexarm
