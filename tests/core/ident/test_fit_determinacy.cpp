// Which free parameters a fit's data determine (fit_detail::assessDeterminacy): a std of 0 or
// nan, a bound, an interval wider than the value; and the combination the data fix least.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ident/fit.h"
#include "core/ident/fit_internal.h"
#include "core/models/physical_models.h"

namespace flexarm {
namespace {

// A two-mass result with J_m and J_a free: J_a's std given, the two strongly correlated.
FitResult twoMassResult(double jaStd, double correlation) {
  FitResult r;
  r.physical = std::shared_ptr<const PhysicalModel>(makeModel("two-mass"));
  const auto& params = r.physical->parameters();
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(params.size()); ++i)
    if (params[static_cast<std::size_t>(i)].name == "J_m" || params[static_cast<std::size_t>(i)].name == "J_a")
      free.push_back(i);
  r.freeIndices = free;
  const double jm = r.physical->value("J_m"), ja = r.physical->value("J_a");
  const double jmStd = 0.01 * jm;
  r.covariance.resize(2, 2);
  const bool jmFirst = params[static_cast<std::size_t>(free[0])].name == "J_m";
  const double s0 = jmFirst ? jmStd : jaStd, s1 = jmFirst ? jaStd : jmStd;
  r.covariance << s0 * s0, correlation * s0 * s1, correlation * s0 * s1, s1 * s1;
  const double z = 2.5758293035489;
  for (const auto& [name, value, sd] : {std::tuple{"J_m", jm, jmStd}, std::tuple{"J_a", ja, jaStd}})
    r.parameters.push_back({name, "kg m^2", value, sd, value - z * sd, value + z * sd, true, "", true, {}});
  r.parameters.push_back({"r", "1", r.physical->value("r"), 0.0, 0.0, 0.0, false, "", true, {}});
  return r;
}

FitOptions physicalOptions() {
  FitOptions o;
  o.model.kind = FitModelKind::Physical;
  o.level = 0.99;
  return o;
}

TEST(FitDeterminacy, AWellDeterminedParameterStaysSoAndAFixedOneIsNotJudged) {
  FitResult r = twoMassResult(0.01 * makeModel("two-mass")->value("J_a"), 0.3);
  fit_detail::assessDeterminacy(physicalOptions(), r);
  for (const auto& p : r.parameters) EXPECT_TRUE(p.determined) << p.name << ": " << p.undetermined;
  EXPECT_EQ(r.undeterminedDirection, "");
}

TEST(FitDeterminacy, AWideIntervalNamesTheCombinationTheDataFixLeast) {
  const double ja = makeModel("two-mass")->value("J_a");
  FitResult r = twoMassResult(0.8 * ja, -0.95);  // 99 % interval +-2.06 J_a
  fit_detail::assessDeterminacy(physicalOptions(), r);
  const FitParameter& a = r.parameters[1];
  EXPECT_FALSE(a.determined);
  EXPECT_EQ(a.undetermined, "its 99 % interval is wider than its value");
  EXPECT_TRUE(r.parameters[0].determined);
  // Relative to the values the J_a direction dominates: J_a first and positive.
  EXPECT_EQ(r.undeterminedDirection.rfind("J_a +", 0), 0u) << r.undeterminedDirection;
}

TEST(FitDeterminacy, AStdOfZeroOrNanOrABoundIsUndetermined) {
  for (double sd : {0.0, std::nan("")}) {
    FitResult r = twoMassResult(sd, 0.0);
    fit_detail::assessDeterminacy(physicalOptions(), r);
    EXPECT_FALSE(r.parameters[1].determined) << sd;
    EXPECT_NE(r.parameters[1].undetermined.find(sd == 0.0 ? "its std is 0" : "no finite std"), std::string::npos)
        << r.parameters[1].undetermined;
  }
  FitResult r = twoMassResult(0.01 * makeModel("two-mass")->value("J_a"), 0.0);
  r.warnings.push_back("J_a sits on its lower bound 1e-09; the data would push it below");
  fit_detail::assessDeterminacy(physicalOptions(), r);
  EXPECT_FALSE(r.parameters[1].determined);
  EXPECT_NE(r.parameters[1].undetermined.find("sits on a bound"), std::string::npos);
}

}  // namespace
}  // namespace flexarm
