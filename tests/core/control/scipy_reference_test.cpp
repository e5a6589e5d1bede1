// LQR and Kalman gains of the seed's three designs against an independent reference:
// SciPy's scipy.linalg.solve_continuous_are, run by /usr/bin/python3 on the same matrices.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "core/control/lqg.h"

namespace flexarm {
namespace {

const char* kScript = R"PY(
import sys
import numpy as np
from scipy.linalg import solve_continuous_are

def read(f):
    rows, cols = map(int, f.readline().split())
    return np.array([float(v) for v in f.readline().split()]).reshape(rows, cols)

with open(sys.argv[1]) as f:
    count = int(f.readline())
    for _ in range(count):
        A, B, Q, R = (read(f) for _ in range(4))
        X = solve_continuous_are(A, B, Q, R)
        print(' '.join('%.17g' % v for v in X.ravel()))
)PY";

struct Problem {
  Eigen::MatrixXd A, B, Q, R;
};

void writeMatrix(std::ostream& out, const Eigen::MatrixXd& M) {
  out << M.rows() << " " << M.cols() << "\n";
  out.precision(17);
  for (Eigen::Index i = 0; i < M.rows(); ++i)
    for (Eigen::Index j = 0; j < M.cols(); ++j) out << M(i, j) << " ";
  out << "\n";
}

// Runs the script on the problems; fails the test (does not skip) when Python or SciPy is
// missing. Returns one solution per problem.
std::vector<Eigen::MatrixXd> scipySolutions(const std::vector<Problem>& problems) {
  const std::string dir = ::testing::TempDir();
  const std::string input = dir + "/flexarm_care_" + std::to_string(::getpid()) + ".txt";
  const std::string script = dir + "/flexarm_care_" + std::to_string(::getpid()) + ".py";
  {
    std::ofstream s(script);
    s << kScript;
    std::ofstream in(input);
    in << problems.size() << "\n";
    for (const auto& p : problems)
      for (const auto* M : {&p.A, &p.B, &p.Q, &p.R}) writeMatrix(in, *M);
  }
  std::vector<Eigen::MatrixXd> out;
  FILE* pipe = ::popen(("/usr/bin/python3 " + script + " " + input + " 2>&1").c_str(), "r");
  if (!pipe) {
    ADD_FAILURE() << "cannot run /usr/bin/python3: the SciPy reference needs python3 with scipy";
    return out;
  }
  std::string text;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) text += buf;
  const int status = ::pclose(pipe);
  std::remove(input.c_str());
  std::remove(script.c_str());
  if (status != 0) {
    ADD_FAILURE() << "/usr/bin/python3 with scipy is required for this reference test; it said:\n"
                  << text;
    return out;
  }
  std::istringstream lines(text);
  for (const auto& p : problems) {
    Eigen::MatrixXd X(p.A.rows(), p.A.cols());
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      for (Eigen::Index j = 0; j < X.cols(); ++j) lines >> X(i, j);
    if (!lines) {
      ADD_FAILURE() << "unexpected output from the SciPy script:\n" << text;
      return {};
    }
    out.push_back(X);
  }
  return out;
}

TEST(ScipyReference, SeedDesignsAgreeWithSolveContinuousAre) {
  const std::vector<LqgOptions> designs = {LqgOptions::seedCaseI(), LqgOptions::seedCaseII(),
                                           LqgOptions::seedAccelerationFeedback()};
  std::vector<Problem> problems;
  std::vector<LqgDesign> results;
  for (const auto& o : designs) {
    results.push_back(designLqg(o));
    ASSERT_TRUE(results.back().ok()) << results.back().message;
    const LqgDesign& d = results.back();
    // The LQR of the four-state arm, then the Kalman filter on the x5 model (dual form).
    problems.push_back({d.plant.A, d.plant.B, Eigen::MatrixXd(o.q1.head(4).asDiagonal()),
                        Eigen::MatrixXd::Constant(1, 1, o.q2)});
    problems.push_back({d.model.A.transpose(), d.model.C.transpose(),
                        Eigen::MatrixXd(o.r1.asDiagonal()), Eigen::MatrixXd(o.r2.asDiagonal())});
  }
  const std::vector<Eigen::MatrixXd> X = scipySolutions(problems);
  ASSERT_EQ(X.size(), problems.size());
  for (std::size_t i = 0; i < designs.size(); ++i) {
    const LqgDesign& d = results[i];
    const Eigen::RowVectorXd L = X[2 * i].row(1) / designs[i].q2;  // Q2^-1 B' X, B = e2 / J_m
    const Eigen::RowVectorXd Lref = L / designs[i].parameters.Jm;
    EXPECT_LT((d.L.head(4) - Lref).norm(), 1e-8 * Lref.norm()) << "design " << i << "\n"
                                                               << d.L << "\n"
                                                               << Lref;
    const Eigen::MatrixXd R2 = designs[i].r2.asDiagonal();
    const Eigen::MatrixXd Kref = X[2 * i + 1] * d.model.C.transpose() * R2.inverse();
    EXPECT_LT((d.K - Kref).norm(), 1e-7 * Kref.norm()) << "design " << i << "\n"
                                                       << d.K.transpose() << "\n"
                                                       << Kref.transpose();
  }
}

}  // namespace
}  // namespace flexarm
