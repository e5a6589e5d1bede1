// flexarm fit --effect end to end: a three-mass log simulated with a stiffening gear spring and
// Coulomb friction (tests/core/ident/nonlinear_logs.h) is fitted with both effects from the
// command line; the JSON lists each effect's parameters with std devs and intervals holding
// the truth, the text names them, --fix holds an effect value, and bad effects are usage
// errors (exit 2) with a sentence.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"
#include "core/io/log_io.h"
#include "tests/core/ident/nonlinear_logs.h"

using namespace flexarm::test;
using nlohmann::json;

namespace {

// The estimation (white torque) and validation (binary torque) logs, written once per process.
struct Logs {
  std::string estimation, validation;
};
const Logs& logs() {
  static const Logs l = [] {
    const auto dir = scratchDir();
    Logs out{(dir / "effects_estimation.csv").string(), (dir / "effects_validation.csv").string()};
    EXPECT_TRUE(flexarm::writeFlexArmCsv(flexarm::testing::nonlinearLog(2500, 0, 11), out.estimation));
    EXPECT_TRUE(flexarm::writeFlexArmCsv(flexarm::testing::nonlinearLog(2500, 1, 12), out.validation));
    return out;
  }();
  return l;
}

}  // namespace

TEST(CliFitEffects, RecoversTheSpringAndTheFrictionWithStdDevs) {
  const auto r = runFlexarm({"fit", logs().estimation, "--model", "three-mass", "--effect", "nonlinear_spring:1e6",
                             "--effect", "coulomb_friction:0.02", "--validation-log", logs().validation,
                             // the truth's d_g is the seed's negative one (Table 5.7)
                             "--bound", "d_g=-inf:inf", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["model"], "three-mass + nonlinear_spring + coulomb_friction (K = 0)");
  ASSERT_EQ(j["effects"].size(), 2u);
  const std::pair<const char*, double> truth[] = {{"beta", 2e6}, {"F_c", 0.05}};
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& p = j["effects"][i]["parameters"][truth[i].first];
    EXPECT_TRUE(p["free"].get<bool>());
    EXPECT_GT(p["std"].get<double>(), 0.0) << p;
    EXPECT_LE(p["lower"].get<double>(), truth[i].second) << p;
    EXPECT_GE(p["upper"].get<double>(), truth[i].second) << p;
    EXPECT_EQ(j["std"][truth[i].first], p["std"]);
  }
  EXPECT_FALSE(j["effects"][1]["parameters"]["v_s"]["free"].get<bool>());
  EXPECT_EQ(j["effects"][0]["spec"].get<std::string>().rfind("nonlinear_spring:", 0), 0u);
  EXPECT_GT(j["fit_percent_validation"].get<double>(), 99.0);

  // Text: the effect parameters with their std devs and units; --fix holds beta.
  const auto t = runFlexarm({"fit", logs().estimation, "--model", "three-mass", "--effect", "nonlinear_spring",
                             "--effect", "coulomb_friction", "--fix", "beta=2e6", "--max-iterations", "5"});
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("beta = 2e+06 +- 0 (fixed) 1/rad^2 (nonlinear_spring)"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("N m (coulomb_friction)"), std::string::npos) << t.out;
}

// The rules (a gear spring for backlash, effects on physical models only, output error) are the
// request's: FitSpec.* and FitNonlinear.* test their codes; here the exit status.
TEST(CliFitEffects, BadEffectsAreUsageErrorsAndHelpDocumentsThem) {
  auto r = runFlexarm({"fit", logs().estimation, "--model", "three-mass", "--effect", "stiction"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown effect 'stiction'"), std::string::npos) << r.err;
  r = runFlexarm({"fit", logs().estimation, "--model", "rigid", "--effect", "backlash"});
  EXPECT_EQ(r.code, 2);
  r = runFlexarm({"fit", logs().estimation, "--model", "oe:2,2,1", "--effect", "backlash"});
  EXPECT_EQ(r.code, 2);
  r = runFlexarm({"fit", logs().estimation, "--model", "three-mass", "--effect", "coulomb_friction",
                  "--noise-model"});
  EXPECT_EQ(r.code, 2);
  r = runFlexarm({"fit", logs().estimation, "--model", "three-mass", "--effect", "coulomb_friction", "--free", "n"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no parameter 'n'"), std::string::npos) << r.err;
  r = runFlexarm({"fit", "--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--effect NAME[:V1,...]"), std::string::npos);
  // Every effect of the registry, with its parameters, in the help (one list for every verb).
  for (const char* line : {"  coulomb_friction:F_c,v_s", "  nonlinear_spring:beta", "  torque_ripple:a_1,n,b_1",
                           "  asymmetric_coulomb:F_c+,F_c-", "  encoder_skew:T_o"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line;
}
