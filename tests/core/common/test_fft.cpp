// realDft (core/common/fft.h) against the DFT's definition, X(k) = sum_t x(t) e^{-i 2 pi k t / n}:
// even and odd lengths, an input that is not at FFTW's alignment, plans shared by threads, and
// many threads planning at the same moment (FFTW's planner is not thread-safe: without the one
// planner lock the last test crashed or returned wrong bins in most runs).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <complex>
#include <condition_variable>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "core/common/fft.h"

namespace flexarm {
namespace {

std::vector<double> noise(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<double> x(static_cast<std::size_t>(n));
  for (double& v : x) v = g(rng);
  return x;
}

// The largest |X(k) - definition| over k = 0..n/2, relative to the largest |X(k)|.
double errorAgainstDefinition(const double* x, int n, const std::vector<std::complex<double>>& X) {
  double err = 0.0, scale = 0.0;
  for (int k = 0; k <= n / 2; ++k) {
    std::complex<double> s = 0.0;
    for (int t = 0; t < n; ++t)
      s += x[t] * std::polar(1.0, -2.0 * M_PI * static_cast<double>(k) * t / n);
    err = std::max(err, std::abs(s - X[static_cast<std::size_t>(k)]));
    scale = std::max(scale, std::abs(s));
  }
  return err / scale;
}

TEST(RealDft, MatchesTheDefinitionAtEvenAndOddLengths) {
  for (int n : {1, 2, 7, 64, 250, 1023}) {
    const auto x = noise(n, static_cast<unsigned>(n));
    std::vector<std::complex<double>> X(static_cast<std::size_t>(n / 2 + 1));
    realDft(x.data(), n, X.data());
    EXPECT_LT(errorAgainstDefinition(x.data(), n, X), 1e-12) << "n = " << n;
    EXPECT_EQ(x, noise(n, static_cast<unsigned>(n))) << "the input was changed, n = " << n;
  }
}

TEST(RealDft, InputOffByOneDoubleFromTheAlignmentGivesTheSameValues) {
  const int n = 512;
  const auto buffer = noise(n + 1, 3);
  std::vector<double> aligned(buffer.begin() + 1, buffer.end());
  std::vector<std::complex<double>> a(n / 2 + 1), b(n / 2 + 1);
  realDft(aligned.data(), n, a.data());
  realDft(buffer.data() + 1, n, b.data());  // 8 bytes past the vector's alignment
  EXPECT_EQ(a, b);
  EXPECT_LT(errorAgainstDefinition(aligned.data(), n, a), 1e-12);
}

TEST(RealDft, ThreadsTransformingManyLengthsAtOnceGetTheSingleThreadedValues) {
  // More lengths than the plans kept, so plans are made and dropped while others run.
  const std::vector<int> lengths{96, 100, 128, 150, 200, 256, 300, 333, 400, 512, 640, 777};
  std::vector<std::vector<std::complex<double>>> expected;
  for (int n : lengths) {
    const auto x = noise(n, 11);
    expected.emplace_back(static_cast<std::size_t>(n / 2 + 1));
    realDft(x.data(), n, expected.back().data());
  }
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int round = 0; round < 50; ++round)
        for (std::size_t i = 0; i < lengths.size(); ++i) {
          const int n = lengths[(i + static_cast<std::size_t>(t)) % lengths.size()];
          const auto x = noise(n, 11);
          std::vector<std::complex<double>> X(static_cast<std::size_t>(n / 2 + 1));
          realDft(x.data(), n, X.data());
          const auto& e = expected[(i + static_cast<std::size_t>(t)) % lengths.size()];
          if (X != e) ++mismatches[static_cast<std::size_t>(t)];
        }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(mismatches[static_cast<std::size_t>(t)], 0) << "thread " << t;
}

TEST(RealDft, ANonPositiveLengthIsMisuse) {
  std::complex<double> X;
  EXPECT_THROW(realDft(nullptr, 0, &X), std::invalid_argument);
}

// Forces the coincidence: every thread waits at one gate, then all plan, execute and destroy
// transforms of many different sizes at once, so planner calls overlap all the time.
TEST(RealDft, ManyThreadsPlanningAtOnceGetCorrectBins) {
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
        const auto x = noise(n, static_cast<unsigned>(id * 1000 + r));
        try {
          std::vector<std::complex<double>> X(static_cast<std::size_t>(n / 2 + 1));
          realDft(x.data(), n, X.data());
          if (errorAgainstDefinition(x.data(), n, X) > 1e-12) ++wrong;
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
