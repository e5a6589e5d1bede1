// The FFT wrapper every FlexArm transform goes through: correct bins, and correct under many
// threads planning at the same moment (FFTW's planner is not thread-safe: without the one
// planner lock this test crashed or returned wrong bins in most runs).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <complex>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "core/common/fft.h"

namespace flexarm {
namespace {

std::vector<double> testSignal(int n, int seed) {
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t) x[static_cast<std::size_t>(t)] = std::sin(0.37 * t + seed) + 0.01 * t;
  return x;
}

// The DFT by its definition, O(n^2).
std::vector<std::complex<double>> naiveDft(const std::vector<double>& x) {
  const int n = static_cast<int>(x.size());
  std::vector<std::complex<double>> X(static_cast<std::size_t>(n / 2 + 1));
  for (int k = 0; k <= n / 2; ++k)
    for (int t = 0; t < n; ++t)
      X[static_cast<std::size_t>(k)] += x[static_cast<std::size_t>(t)] *
                                        std::polar(1.0, -2.0 * M_PI * k * t / n);
  return X;
}

double maxError(const std::vector<std::complex<double>>& a,
                const std::vector<std::complex<double>>& b) {
  if (a.size() != b.size()) return INFINITY;
  double e = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) e = std::max(e, std::abs(a[i] - b[i]));
  return e;
}

TEST(RealFft, MatchesTheDefinition) {
  for (int n : {1, 2, 3, 7, 8, 31, 64, 100}) {
    const auto x = testSignal(n, n);
    EXPECT_LT(maxError(realDft(x.data(), n), naiveDft(x)), 1e-9 * n) << "n = " << n;
  }
  EXPECT_THROW(RealFft(0), std::invalid_argument);
}

TEST(RealFft, ReusedPlanGivesTheSameBins) {
  RealFft fft(12);
  const auto x = testSignal(12, 1);
  std::copy(x.begin(), x.end(), fft.input());
  const std::vector<std::complex<double>> first(fft.transform(), fft.transform() + fft.bins());
  std::copy(x.begin(), x.end(), fft.input());
  const std::complex<double>* again = fft.transform();
  for (int k = 0; k < fft.bins(); ++k) EXPECT_EQ(first[static_cast<std::size_t>(k)], again[k]);
}

// Forces the coincidence: every thread waits at one gate, then all plan, execute and destroy
// transforms of many different sizes at once, so planner calls overlap all the time.
TEST(RealFft, ManyThreadsPlanningAtOnceGetCorrectBins) {
  const int threads = 8, rounds = 150;
  std::mutex m;
  std::condition_variable cv;
  bool open = false;
  std::atomic<int> wrong{0}, thrown{0};
  std::vector<std::thread> pool;
  for (int id = 0; id < threads; ++id)
    pool.emplace_back([&, id] {
      {
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return open; });
      }
      for (int r = 0; r < rounds; ++r) {
        const int n = 5 + (r * 13 + id * 29) % 97;  // sizes that are mostly not powers of 2
        const auto x = testSignal(n, id + r);
        try {
          if (maxError(realDft(x.data(), n), naiveDft(x)) > 1e-9 * n) ++wrong;
        } catch (const std::exception&) {
          ++thrown;
        }
      }
    });
  {
    std::lock_guard<std::mutex> lock(m);
    open = true;
  }
  cv.notify_all();
  for (auto& t : pool) t.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_EQ(thrown.load(), 0);
}

}  // namespace
}  // namespace flexarm
