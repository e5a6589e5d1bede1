// The model and simulate verbs end to end: printed matrices against the seed's formulas,
// deterministic logs with their truth, and the exit codes for bad requests.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "core/io/log_io.h"

using flexarm::test::readAll;
using flexarm::test::runFlexarm;
using nlohmann::json;

TEST(CliModels, TwoMassMatricesAreThoseOf313WithTable52) {
  auto r = runFlexarm({"model", "--model", "two-mass", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  json j = json::parse(r.out);
  const double Jm = 9e-4, Ja = 12, fm = 0.1, k = 1.5e5, d = 70, rr = 1.0 / 118;
  const auto& A = j["continuous"]["A"];
  EXPECT_NEAR(A[0][1].get<double>(), rr, 1e-12);
  EXPECT_NEAR(A[1][0].get<double>(), -rr * k / Jm, 1e-6);
  EXPECT_NEAR(A[1][1].get<double>(), -(fm + rr * rr * d) / Jm, 1e-9);
  EXPECT_NEAR(A[2][0].get<double>(), k / Ja, 1e-9);
  EXPECT_NEAR(A[2][2].get<double>(), -d / Ja, 1e-12);
  EXPECT_NEAR(j["continuous"]["B"][1][0].get<double>(), 1 / Jm, 1e-6);
  // (5.4): the notch near sqrt(k / J_a) = 112 rad/s.
  ASSERT_EQ(j["notches_rad_s"].size(), 1u);
  EXPECT_NEAR(j["notches_rad_s"][0].get<double>(), 112.0, 0.5);
  ASSERT_EQ(j["lightly_damped_zeros"].size(), 1u);
  EXPECT_NEAR(j["lightly_damped_zeros"][0]["frequency_rad_s"].get<double>(), 112.0, 0.5);
}

TEST(CliModels, ParametersMoveTheNotchAndBadOnesAreRefused) {
  auto r = runFlexarm({"model", "--model", "two-mass", "--param", "k_a=6e5", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NEAR(json::parse(r.out)["notches_rad_s"][0].get<double>(), 223.5, 1.0);
  EXPECT_EQ(runFlexarm({"model", "--model", "two-mass", "--param", "k_g=1"}).code, 2)
      << "two-mass has no k_g";
  EXPECT_EQ(runFlexarm({"model", "--model", "five-mass"}).code, 2);
  auto neg = runFlexarm({"model", "--model", "two-mass", "--param", "J_m=-1"});
  EXPECT_EQ(neg.code, 2);
  EXPECT_NE(neg.err.find("J_m"), std::string::npos) << neg.err;
}

TEST(CliModels, ThreeMassHasTwoResonances) {
  auto r = runFlexarm({"model", "--model", "three-mass", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  json j = json::parse(r.out);
  EXPECT_EQ(j["notches_rad_s"].size(), 2u);
  EXPECT_EQ(j["peaks_rad_s"].size(), 2u);
  EXPECT_EQ(j["poles"].size(), 5u);
}

TEST(CliModels, SimulateWritesADeterministicLogAndItsTruth) {
  const auto dir = flexarm::test::scratchDir();
  const std::string a = (dir / "a.csv").string(), b = (dir / "b.csv").string(), c = (dir / "c.csv").string();
  const std::vector<std::string> common = {"simulate", "--model", "two-mass", "--effect",
                                           "backlash:1e-4", "--excitation", "prbs", "--duration",
                                           "1.5", "--rate", "1000"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    return runFlexarm(args);
  };
  ASSERT_EQ(with({"--seed", "5", "--out", a}).code, 0);
  ASSERT_EQ(with({"--seed", "5", "--out", b}).code, 0);
  ASSERT_EQ(with({"--seed", "6", "--out", c}).code, 0);
  EXPECT_EQ(readAll(a), readAll(b)) << "same seed, same bytes";
  EXPECT_NE(readAll(a), readAll(c)) << "another seed, another log";
  flexarm::LogReadResult log = flexarm::readLog(a);
  ASSERT_TRUE(log.ok) << log.error.toString();
  EXPECT_NEAR(log.data.sampleRateHz(), 1000.0, 1e-9);
  EXPECT_EQ(log.data.samples(), 1500u);
  EXPECT_TRUE(log.data.isClosedLoop());
  json truth = json::parse(readAll((dir / "a.truth.json").string()));
  EXPECT_EQ(truth["seed"].get<int>(), 5);
  EXPECT_NE(truth.dump().find("backlash"), std::string::npos);
}

TEST(CliModels, SimulateRefusesBadRequestsAndReportsAnUnstableLoop) {
  const std::string out = (flexarm::test::scratchDir() / "x.csv").string();
  EXPECT_EQ(runFlexarm({"simulate", "--effect", "gearbox_rattle", "--out", out}).code, 2);
  EXPECT_EQ(runFlexarm({"simulate", "--duration", "-1", "--out", out}).code, 2);
  EXPECT_EQ(runFlexarm({"simulate", "--duration", "1"}).code, 2) << "no --out";
  auto r = runFlexarm({"simulate", "--model", "two-mass", "--kv", "50", "--duration", "2", "--out", out});
  EXPECT_EQ(r.code, 4);
  EXPECT_FALSE(r.err.empty());
  EXPECT_FALSE(std::filesystem::exists(out)) << "no log from a diverged simulation";
}

// The "From MATLAB" table (docs/from-matlab.md): every FlexArm verb it names exists and every option it gives
// that verb is one the verb's --help lists (--effect, --start and --bound of `fit` belong to
// the nonlinear grey-box fit that lands beside this and are checked once it does).
TEST(CliModels, FromMatlabPageNamesRealVerbsAndOptions) {
  const std::string section = readAll(std::string(FLEXARM_SAMPLE_DIR) + "/../docs/from-matlab.md");
  ASSERT_EQ(section.rfind("# From MATLAB", 0), 0u);
  for (const char* matlab : {"spa(", "etfe(", "tfest", "greyest", "idnlgrey", "compare(", "iddata"})
    EXPECT_NE(section.find(matlab), std::string::npos) << matlab;
  // `flexarm VERB ...` up to the closing backtick.
  std::map<std::string, std::string> helpOf;
  int checked = 0;
  for (std::size_t at = section.find("`flexarm "); at != std::string::npos;
       at = section.find("`flexarm ", at + 1)) {
    const std::string command = section.substr(at + 9, section.find('`', at + 1) - at - 9);
    const std::string verb = command.substr(0, command.find(' '));
    if (!helpOf.count(verb)) {
      const auto h = runFlexarm({verb, "--help"});
      ASSERT_EQ(h.code, 0) << verb << ": " << h.err;
      helpOf[verb] = h.out;
    }
    for (std::size_t o = command.find("--"); o != std::string::npos; o = command.find("--", o + 2)) {
      const std::string option = command.substr(o, command.find_first_of(" =[", o) - o);
      if (option == "--help") continue;
      EXPECT_NE(helpOf[verb].find(option), std::string::npos) << "flexarm " << verb << " " << option << " (in " << command << ")";
      ++checked;
    }
  }
  EXPECT_GT(checked, 15);
}
