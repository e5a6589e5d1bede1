#pragma once
// What the hostile-input tests share: a run held to a time limit and traced (strace), and the
// check every hostile run ends with: its exit code and sentence, no crash, a memory ceiling,
// the time limit, and nothing touched outside the test's folder.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli_test_support.h"

namespace flexarm::test {

inline MeasuredRun confined(const std::vector<std::string>& args, int seconds = 60) {
  RunLimits limits;
  limits.timeoutSeconds = kUnderAddressSanitizer ? 4 * seconds : seconds;
  limits.traceFiles = true;
  return runFlexarmMeasured(args, limits);
}

inline std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

inline void expectConfined(const MeasuredRun& r, int code, const std::string& needle, long memoryMb) {
  EXPECT_FALSE(r.timedOut) << "still running at the time limit; " << r.err;
  EXPECT_EQ(r.code, code) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  EXPECT_LT(r.maxRssMb, ceilingMb(memoryMb)) << r.err;
  EXPECT_TRUE(r.traced) << "strace is needed to see what the run touched";
  EXPECT_TRUE(r.outsideAccess.empty()) << joined(r.outsideAccess);
}

}  // namespace flexarm::test
