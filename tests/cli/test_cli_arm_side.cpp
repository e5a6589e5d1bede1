// The arm side end to end: `flexarm simulate --arm-angle` writes an arm-side encoder, `flexarm
// fit` on it reports the deflection it predicts (JSON `deflection` with the fit's own keys),
// `--outputs motor,arm` fits both outputs, and `--method idim` reproduces the EMPS reference
// (tests/data/emps) in the units of a prismatic axis.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"

using namespace flexarm::test;
using nlohmann::json;

namespace {

const std::string& armLog() {
  static const std::string path = [] {
    const std::string p = (scratchDir() / "arm_angle.csv").string();
    const auto r = runFlexarm({"simulate", "--model", "two-mass", "--arm-angle", "--load-noise", "0.2", "--duration",
                               "4", "--seed", "5", "--out", p});
    EXPECT_EQ(r.code, 0) << r.err;
    return p;
  }();
  return path;
}

}  // namespace

TEST(CliArmSide, SimulateWritesTheArmAngleAndFitReportsTheDeflection) {
  EXPECT_NE(readAll(armLog()).find("arm_angle_rad"), std::string::npos);
  const auto r = runFlexarm({"fit", armLog(), "--model", "two-mass", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_TRUE(j["deflection"].is_object()) << j.dump(1);
  const json& d = j["deflection"];
  for (const char* key : {"fit_percent", "fit_percent_validation", "fit_percent_nrmse", "fit_percent_validation_nrmse",
                          "rms_estimation", "rms_validation", "skew_s", "gear_ratio"})
    EXPECT_TRUE(d.contains(key)) << key;
  EXPECT_GT(d["fit_percent"].get<double>(), 95.0);
  EXPECT_LT(d["rms_estimation"].get<double>(), 0.25 * d["measured_rms"].get<double>());
  EXPECT_TRUE(j["plausibility"].empty()) << j["plausibility"].dump();
  // The text says it too.
  const auto text = runFlexarm({"fit", armLog(), "--model", "two-mass"});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("deflection r phi_m - phi_a"), std::string::npos) << text.out;
}

TEST(CliArmSide, BothOutputsTogether) {
  const auto r = runFlexarm({"fit", armLog(), "--model", "two-mass", "--outputs", "motor,arm", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_NE(j["model"].get<std::string>().find("motor and arm"), std::string::npos) << j["model"];
  ASSERT_TRUE(j["deflection"].is_object());
  EXPECT_GT(j["deflection"]["fit_percent"].get<double>(), 95.0);
  // The truth (Table 5.2) comes back.
  EXPECT_NEAR(j["parameters"]["k_a"].get<double>(), 1.5e5, 0.03 * 1.5e5);
  EXPECT_NEAR(j["parameters"]["J_a"].get<double>(), 12.0, 0.03 * 12.0);
  const auto bad = runFlexarm({"fit", armLog(), "--model", "two-mass", "--outputs", "arm"});
  EXPECT_EQ(bad.code, 2) << bad.err;
  // A skew between encoders means nothing without the arm encoder as an output.
  const auto skew = runFlexarm({"fit", armLog(), "--model", "two-mass", "--effect", "encoder_skew"});
  EXPECT_EQ(skew.code, 2) << skew.err;
  EXPECT_NE(skew.err.find("--outputs motor,arm"), std::string::npos) << skew.err;
}

TEST(CliArmSide, IdimReproducesTheEmpsReference) {
  const std::string emps = std::string(FLEXARM_TEST_DATA_DIR) + "/emps/DATA_EMPS.mat";
  const auto r = runFlexarm({"fit", emps, "--input-var", "vir", "--output-var", "qm", "--output-name",
                             "load_position_m", "--sample-time", "0.001", "--model", "rigid", "--method", "idim",
                             "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_TRUE(j["idim"].is_object()) << j.dump(1);
  const json& p = j["idim"]["parameters"];
  // The input is the controller's output in V: the force is gtau = 35.15 N/V times it.
  const double gtau = 35.15;
  EXPECT_EQ(p["M"]["unit"], "kg");
  EXPECT_NEAR(gtau * p["M"]["value"].get<double>(), 95.1089, 0.02 * 95.1089);
  EXPECT_NEAR(gtau * p["F_c"]["value"].get<double>(), 20.3935, 0.02 * 20.3935);
  EXPECT_NEAR(gtau * p["offset"]["value"].get<double>(), -3.1648, 0.02 * 3.1648);
  EXPECT_LT(j["idim"]["relative_error_percent"].get<double>(), 6.0);
  const auto bad = runFlexarm({"fit", emps, "--input-var", "vir", "--output-var", "qm", "--sample-time", "0.001",
                               "--model", "rigid", "--method", "newton"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("pem, idim or idim-iv"), std::string::npos) << bad.err;
}
