// State-space fits and the order scan through the executable, on the real DaISy arm: `fit
// --model ss` (the order chosen by the data, its singular values and reason in the JSON) and
// `fit --scan` (every ARX structure's validation loss, the picks, the state-space orders).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"

using flexarm::test::runFlexarm;
using nlohmann::json;

namespace {

const std::string kDaisy = std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat";

std::vector<std::string> daisy(std::vector<std::string> args) {
  args.insert(args.begin() + 1, kDaisy);
  for (const char* a : {"--input-column", "1", "--output-column", "2", "--range", "0:699", "--validation-range",
                        "700:1023", "--json"})
    args.push_back(a);
  return args;
}

TEST(CliSubspace, StateSpaceFitOfTheDaisyArmSaysItsOrderAndWhy) {
  const auto r = runFlexarm(daisy({"fit", "--model", "ss"}));
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  const json& s = j["subspace"];
  ASSERT_TRUE(s.is_object()) << r.out.substr(0, 400);
  const int n = s["chosen_order"].get<int>();
  EXPECT_EQ(j["model"], "ss[" + std::to_string(n) + "]");
  EXPECT_GE(n, 4);
  EXPECT_LE(n, 12);
  EXPECT_EQ(s["method"], "cva");  // open loop: no reference channel
  EXPECT_GT(s["singular_values"].size(), static_cast<std::size_t>(n));
  EXPECT_EQ(s["orders"].size(), 12u);
  EXPECT_NE(s["order_reason"].get<std::string>().find("least MDL"), std::string::npos);
  EXPECT_EQ(j["parameters"].size(), static_cast<std::size_t>(3 * n));
  for (const auto& row : j["parameter_rows"]) {
    ASSERT_TRUE(row["std"].is_number()) << row;
    EXPECT_GT(row["std"].get<double>(), 0.0) << row;
  }
  EXPECT_GT(j["fit_percent_validation"].get<double>(), 95.0);
  // A given order is kept.
  const auto four = runFlexarm(daisy({"fit", "--model", "ss:4"}));
  ASSERT_EQ(four.code, 0) << four.err;
  const json k = json::parse(four.out);
  EXPECT_EQ(k["model"], "ss[4]");
  EXPECT_EQ(k["subspace"]["orders"].size(), 1u);
  EXPECT_NE(k["subspace"]["order_reason"].get<std::string>().find("as asked"), std::string::npos);
}

TEST(CliSubspace, OrderScanListsEveryStructureAndItsPicks) {
  const auto r = runFlexarm(daisy({"fit", "--model", "arx:6,6,2", "--scan"}));
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["format"], "flexarm-order-scan");
  EXPECT_EQ(j["loss_on"], "validation");
  ASSERT_EQ(j["arx"].size(), 7u * 6u * 2u);
  // The pick of least validation loss is the row of least loss.
  double least = 1e300;
  std::string name;
  for (const auto& row : j["arx"])
    if (row["loss"].get<double>() < least) {
      least = row["loss"].get<double>();
      name = "arx[" + std::to_string(row["na"].get<int>()) + " " + std::to_string(row["nb"].get<int>()) + " " +
             std::to_string(row["nk"].get<int>()) + "]";
    }
  EXPECT_EQ(j["best_validation"], name);
  EXPECT_TRUE(j["best_mdl"].is_string());
  EXPECT_TRUE(j["state_space"]["chosen_order"].is_number());
  // The text names the picks.
  std::vector<std::string> text = {"fit", kDaisy, "--model", "arx:6,6,2", "--scan", "--range", "0:699",
                                   "--validation-range", "700:1023"};
  const auto t = runFlexarm(text);
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("least validation loss (selstruc 0): " + name), std::string::npos) << t.out;
  // Only ARX bounds or a state-space order can be scanned.
  const auto bad = runFlexarm(daisy({"fit", "--model", "oe:2,2,1", "--scan"}));
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--scan"), std::string::npos) << bad.err;
}

}  // namespace
