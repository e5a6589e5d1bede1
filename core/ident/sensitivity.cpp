#include "core/ident/sensitivity.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>

namespace flexarm {

bool AttractionOptions::isValid(std::string* why) const {
  auto fail = [&](const char* t) {
    if (why) *why = t;
    return false;
  };
  if (!(successTolerance > 0.0)) return fail("successTolerance must be positive");
  if (!(maxFactor > 1.0)) return fail("maxFactor must exceed 1");
  if (!(minFactor > 0.0 && minFactor < 1.0)) return fail("minFactor must lie in (0, 1)");
  if (halvings < 1 || threads < 0) return fail("halvings >= 1 and threads >= 0 required");
  return pem.isValid(why);
}

bool MonteCarloOptions::isValid(std::string* why) const {
  auto fail = [&](const char* t) {
    if (why) *why = t;
    return false;
  };
  if (runs < 1) return fail("runs must be at least 1");
  if (!(regionFraction > 0.0 && regionFraction <= 1.0)) return fail("regionFraction in (0, 1]");
  if (!(successTolerance > 0.0) || threads < 0) return fail("bad tolerance or thread count");
  return pem.isValid(why);
}

namespace {

using Clock = std::chrono::steady_clock;

int threadCount(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs job(i) for i in [0, n) on `threads` workers; progress after each job under a mutex;
// returns false when cancelled.
bool parallelFor(int n, int threads, const std::function<void(int)>& job,
                 const ProgressCallback& progress, const std::string& stage) {
  std::atomic<int> next{0}, done{0};
  std::atomic<bool> cancel{false};
  std::mutex mtx;
  auto worker = [&]() {
    for (;;) {
      if (cancel) return;
      const int i = next++;
      if (i >= n) return;
      job(i);
      const int d = ++done;
      std::lock_guard<std::mutex> lock(mtx);
      if (reportProgress(progress, static_cast<double>(d) / n, stage)) cancel = true;
    }
  };
  std::vector<std::thread> pool;
  const int t = std::min(threads, n);
  for (int k = 1; k < t; ++k) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  return !cancel;
}

double fitLoss(const ParametricModel& start, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
               double T, const PemOptions& opt) {
  PemOptions o = opt;
  o.randomStarts = 0;
  o.notchPeakStarts = 0;
  o.userStarts.clear();
  // A search that steps outside a parameter's bounds throws; from a random start that is a
  // failed fit, and it must not leave a worker thread through an exception.
  try {
    const PemResult r = pem(start, u, y, T, o);
    return r.summary.ok() ? r.summary.loss : INFINITY;
  } catch (const std::invalid_argument&) {
    return INFINITY;
  }
}

}  // namespace

AttractionResult domainOfAttraction(const ParametricModel& estimated, const Eigen::VectorXd& u,
                                    const Eigen::VectorXd& y, double T,
                                    const AttractionOptions& options,
                                    const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("domainOfAttraction: " + why);
  const auto t0 = Clock::now();
  AttractionResult r;
  const auto& params = estimated.parameters();
  // The reference: refit from the estimate itself.
  r.referenceLoss = fitLoss(estimated, u, y, T, options.pem);
  if (!std::isfinite(r.referenceLoss)) {
    r.message = "the reference fit from the estimate fails";
    return r;
  }
  std::vector<int> free;
  for (std::size_t i = 0; i < params.size(); ++i)
    if (params[i].free) free.push_back(static_cast<int>(i));
  // One job per (parameter, side): each does its own interval halving.
  const int jobs = static_cast<int>(free.size()) * 2;
  r.parameters.resize(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) r.parameters[i].name = params[free[i]].name;
  std::vector<int> jobFits(jobs, 0);  // one slot per job: no shared writes
  std::atomic<int> fits{0};
  auto succeeds = [&](int idx, double factor) {
    auto m = estimated.clone();
    const double v = params[idx].value * factor;
    if (v < params[idx].lower || v > params[idx].upper) return false;
    m->setParameter(params[idx].name, v);
    ++fits;
    return fitLoss(*m, u, y, T, options.pem) < (1.0 + options.successTolerance) * r.referenceLoss;
  };
  auto job = [&](int k) {
    const int pi = k / 2;
    const bool upper = k % 2 == 0;
    const int idx = free[pi];
    auto& pa = r.parameters[pi];  // upper and lower jobs write different members
    const bool linear = !upper && params[idx].lower < 0.0;
    double good = 1.0;
    double bad = upper ? options.maxFactor : (linear ? -options.maxFactor : options.minFactor);
    bool open = false;
    int count = 0;
    if (succeeds(idx, bad)) {
      good = bad;
      open = true;
      ++count;
    } else {
      ++count;
      for (int h = 0; h < options.halvings; ++h) {
        const double mid = linear ? 0.5 * (good + bad) : std::sqrt(good * bad);
        (succeeds(idx, mid) ? good : bad) = mid;
        ++count;
      }
    }
    if (upper) {
      pa.upperFactor = good;
      pa.upperOpen = open;
    } else {
      pa.lowerFactor = good;
      pa.lowerOpen = open;
    }
    jobFits[k] = count;
  };
  const bool finished = parallelFor(jobs, threadCount(options.threads), job, progress,
                                    "domain of attraction");
  r.fits = fits;
  for (int k = 0; k < jobs; ++k) r.parameters[k / 2].fits += jobFits[k];
  r.termination = finished ? Termination::Converged : Termination::Cancelled;
  r.message = finished ? "interval halving finished for " + std::to_string(free.size()) +
                             " parameters (" + std::to_string(r.fits) + " fits)"
                       : "cancelled by the user; the limits are incomplete";
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

MonteCarloResult monteCarloStarts(const ParametricModel& estimated, const Eigen::VectorXd& u,
                                  const Eigen::VectorXd& y, double T,
                                  const AttractionResult& region,
                                  const MonteCarloOptions& options,
                                  const ProgressCallback& progress) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("monteCarloStarts: " + why);
  const auto t0 = Clock::now();
  MonteCarloResult r;
  r.runs = options.runs;
  r.losses.assign(options.runs, NAN);
  r.success.assign(options.runs, false);
  r.referenceLoss = region.referenceLoss > 0.0 ? region.referenceLoss
                                               : fitLoss(estimated, u, y, T, options.pem);
  if (!std::isfinite(r.referenceLoss)) {
    r.message = "the reference fit from the estimate fails";
    return r;
  }
  const auto& params = estimated.parameters();
  // Draw every start before running so that results do not depend on thread timing.
  std::mt19937 rng(options.seed);
  std::vector<std::vector<std::pair<int, double>>> starts(options.runs);
  for (auto& s : starts)
    for (const auto& pa : region.parameters) {
      const int idx = estimated.indexOf(pa.name);
      if (idx < 0) throw std::invalid_argument("monteCarloStarts: unknown parameter " + pa.name);
      const double f = options.regionFraction;
      std::uniform_real_distribution<double> ud(1.0 + f * (pa.lowerFactor - 1.0),
                                                1.0 + f * (pa.upperFactor - 1.0));
      s.push_back({idx, params[idx].value * ud(rng)});
    }
  std::atomic<int> completed{0}, successes{0};
  std::vector<char> ok(options.runs, 0);  // not vector<bool>: workers write concurrently
  auto job = [&](int i) {
    auto m = estimated.clone();
    for (const auto& [idx, v] : starts[i]) m->setParameter(params[idx].name, v);
    const double loss = fitLoss(*m, u, y, T, options.pem);
    r.losses[i] = loss;
    ok[i] = loss < (1.0 + options.successTolerance) * r.referenceLoss;
    ++completed;
    if (ok[i]) ++successes;
  };
  const bool finished = parallelFor(options.runs, threadCount(options.threads), job, progress,
                                    "Monte-Carlo starts");
  r.completed = completed;
  r.successes = successes;
  for (int i = 0; i < options.runs; ++i) r.success[i] = ok[i] != 0;
  r.termination = finished ? Termination::Converged : Termination::Cancelled;
  r.message = std::to_string(r.successes) + " of " + std::to_string(r.completed) +
              " fits from random initial values reached a loss within " +
              std::to_string(static_cast<int>(std::lround(options.successTolerance * 100))) +
              " % of the original" + (finished ? "" : " (cancelled)");
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

}  // namespace flexarm
