#pragma once
// The DaISy flexible robot arm (96-009, sample_logs/daisy_robot_arm.dat: headerless, column 1
// the input, column 2 the output, T = 1) with its means removed, for the tests that fit it.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "core/ident/nonparametric.h"
#include "core/io/log_io.h"

namespace flexarm::testing {

// False (after a test failure naming the problem) when the file cannot be read.
inline bool daisyRobotArm(Eigen::VectorXd& u, Eigen::VectorXd& y) {
  LogReadOptions opt;
  opt.format = LogFormat::Table;
  const auto read = readTable(FLEXARM_SAMPLE_DIR "/daisy_robot_arm.dat", opt);
  EXPECT_TRUE(read.ok) << read.error.toString();
  if (!read.ok) return false;
  inputOutput(read.data, u, y);
  u.array() -= u.mean();
  y.array() -= y.mean();
  return true;
}

}  // namespace flexarm::testing
