// The session part "diagnosis": its request survives the round trip through JSON with every
// option and threshold, malformed sections are refused with a sentence, and the part is
// registered for replay.
#include <gtest/gtest.h>

#include "core/session/diagnosis_part.h"
#include "core/session/session_part.h"

namespace flexarm {
namespace {

TEST(DiagnosisPart, RequestRoundTrip) {
  DiagnosisSessionRequest q;
  q.log = "step";
  q.referenceLog = "healthy";
  q.model = "";
  q.structure = "three-mass";
  q.seedFault = std::make_pair(std::string("f_m"), 1.2);
  q.options.tests = {DiagnosisTest::Robust, DiagnosisTest::Cusum};
  q.options.decision = {DiagnosisTest::Cusum};
  q.options.window = HypothesisWindow::Cumulative;
  q.options.cusumScales = {0.3, 0.4, 1.5};
  q.options.predictor = DiagnosisPredictor::Direct;
  q.calibration = {{"message", "calibrated"}};
  std::string why;
  const auto back = diagnosisRequestFromJson(diagnosisRequestToJson(q), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->log, "step");
  EXPECT_EQ(back->referenceLog, "healthy");
  ASSERT_TRUE(back->seedFault);
  EXPECT_EQ(back->seedFault->first, "f_m");
  EXPECT_DOUBLE_EQ(back->seedFault->second, 1.2);
  EXPECT_EQ(back->options.tests, q.options.tests);
  EXPECT_EQ(back->options.decision, q.options.decision);
  EXPECT_EQ(back->options.window, HypothesisWindow::Cumulative);
  EXPECT_EQ(back->options.cusumScales, q.options.cusumScales);
  EXPECT_EQ(back->options.robustScales, DiagnosisOptions{}.robustScales);
  EXPECT_EQ(back->options.predictor, DiagnosisPredictor::Direct);
  EXPECT_EQ(back->calibration["message"], "calibrated");
}

TEST(DiagnosisPart, MalformedSectionsAreRefused) {
  const SessionPart* part = findSessionPart("diagnosis");
  ASSERT_NE(part, nullptr);
  std::string why;
  EXPECT_FALSE(part->validate(nlohmann::json::array(), &why));
  nlohmann::json section = {{"request", diagnosisRequestToJson(DiagnosisSessionRequest{})}};
  EXPECT_TRUE(part->validate(section, &why)) << why;
  section["request"]["options"]["tests"] = {"bayes"};
  EXPECT_FALSE(part->validate(section, &why));
  EXPECT_NE(why.find("bayes"), std::string::npos) << why;
  section["request"]["options"]["tests"] = {"cusum"};
  section["request"]["options"]["decision"] = {"robust"};  // not run
  EXPECT_FALSE(part->validate(section, &why));
  EXPECT_NE(why.find("robust"), std::string::npos) << why;
  section["request"]["options"]["decision"] = {"cusum"};
  EXPECT_TRUE(part->validate(section, &why)) << why;
  section["request"]["options"]["cusum_factors"] = {1.0};  // one per parameter needed
  EXPECT_FALSE(part->validate(section, &why));
  EXPECT_NE(why.find("one value per monitored parameter"), std::string::npos) << why;
  section["request"]["options"].erase("cusum_factors");
  section["request"]["structure"] = "five-mass";
  EXPECT_FALSE(part->validate(section, &why));
  EXPECT_NE(why.find("five-mass"), std::string::npos) << why;
}

}  // namespace
}  // namespace flexarm
