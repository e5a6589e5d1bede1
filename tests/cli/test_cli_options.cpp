// The option tables (app/cli/cli.h): `flexarm VERB --help` is written from the table the parser
// uses, so every option it lists is one the parser knows, with the range and default it checks;
// a value outside its range or choices is refused with a sentence naming the option.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>
#include <vector>

#include "cli_test_support.h"

using flexarm::test::runFlexarm;

namespace {

const std::string kDaisy = std::string(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat";

// The options a help text lists at the start of its lines ("  --name VALUE  help").
std::vector<std::string> listedOptions(const std::string& help) {
  std::vector<std::string> names;
  const std::regex line(R"((^|\n)  --([a-z][a-z0-9-]*))");
  for (auto it = std::sregex_iterator(help.begin(), help.end(), line); it != std::sregex_iterator(); ++it)
    names.push_back((*it)[2]);
  return names;
}

TEST(CliOptions, EveryOptionTheHelpListsIsOneTheParserKnows) {
  for (const char* verb : {"fit", "bode"}) {
    const auto help = runFlexarm({verb, "--help"});
    ASSERT_EQ(help.code, 0) << help.err;
    const auto names = listedOptions(help.out);
    EXPECT_GT(names.size(), 30u) << verb << ":\n" << help.out;
    std::set<std::string> seen;
    for (const auto& n : names) {
      EXPECT_TRUE(seen.insert(n).second) << verb << " lists --" << n << " twice";
      const auto r = runFlexarm({verb, "--" + n});
      EXPECT_EQ(r.err.find("unknown option"), std::string::npos) << verb << " --" << n << ": " << r.err;
    }
    for (auto line : {"  --max-iterations N", "  --closed-loop auto|direct|two-stage|indirect", "  --input-column N"}) {
      EXPECT_NE(help.out.find(line), std::string::npos) << verb << ": " << line;
    }
  }
  // The facts the parser checks are the ones the help prints (lines wrapped as they come).
  std::string help;
  for (char c : runFlexarm({"fit", "--help"}).out)
    if (!(c == ' ' || c == '\n') || (!help.empty() && help.back() != ' ')) help += c == '\n' ? ' ' : c;
  EXPECT_NE(help.find("(from 1 to 100000; default 100)"), std::string::npos) << help;
  EXPECT_NE(help.find("(from 0 to 1000; default 0)"), std::string::npos) << help;  // --starts
  EXPECT_NE(help.find("(repeatable)"), std::string::npos) << help;
  EXPECT_NE(help.find("(required)"), std::string::npos) << help;  // --model
}

TEST(CliOptions, ValuesOutsideTheirRangeOrChoicesNameTheOption) {
  auto r = runFlexarm({"fit", kDaisy, "--model", "oe:2,2,1", "--max-iterations", "0"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--max-iterations expects a whole number from 1 to 100000, got '0'"), std::string::npos)
      << r.err;
  r = runFlexarm({"fit", kDaisy, "--model", "oe:2,2,1", "--decimate", "2.5"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--decimate expects a whole number"), std::string::npos) << r.err;
  r = runFlexarm({"fit", kDaisy, "--model", "two-mass", "--seed", "-1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--seed"), std::string::npos) << r.err;
  r = runFlexarm({"fit", kDaisy, "--model", "two-mass", "--outputs", "arm"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--outputs expects motor or motor,arm, not 'arm'"), std::string::npos) << r.err;
  r = runFlexarm({"bode", kDaisy, "--model", "spa", "--out", "/tmp/never.csv", "--level", "1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--level expects a number strictly between 0 and 1, got '1'"), std::string::npos) << r.err;
  r = runFlexarm({"fit", kDaisy});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--model is required"), std::string::npos) << r.err;
  r = runFlexarm({"fit", kDaisy, "--model", "oe:2,2,1", "--json=yes"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--json takes no value"), std::string::npos) << r.err;
}

}  // namespace
