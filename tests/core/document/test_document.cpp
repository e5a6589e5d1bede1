// The Qt-free document (core/document): results are kept only beside their data, ranges in
// seconds, and the data every evaluation takes.
#include <gtest/gtest.h>

#include "core/document/document.h"

namespace flexarm {
namespace {

TEST(Document, AResultIsKeptOnlyBesideItsData) {
  Document d;
  IdData log;
  log.sampleTime = 0.01;
  log.setChannel(Channel{"torque_ref_nm", "N m", ChannelRole::Input, std::vector<double>(100, 0.0)});
  log.setChannel(Channel{"motor_angle_rad", "rad", ChannelRole::Output, std::vector<double>(100, 1.0)});
  d.setLog(log, "/tmp/a/chirp.csv");
  d.setLogSha256("ab");
  EXPECT_EQ(d.dataProvenance().log, "chirp.csv");
  d.setRange(DataRange::Validation, SecondsRange{0.8, 0.2});  // swapped into order
  EXPECT_DOUBLE_EQ(d.range(DataRange::Validation)->start, 0.2);
  EXPECT_EQ(d.samples(DataRange::Validation).size(), 61u);
  const EvaluationData e = d.evaluationData();
  EXPECT_EQ(e.name, "chirp.csv");
  EXPECT_TRUE(e.validation.has_value());
  EXPECT_TRUE(d.recordResult("fit", d.dataProvenance()));
  EXPECT_TRUE(d.recordResult("recursive", d.dataProvenance(), true));
  // Preprocessing withdraws what was computed on the data before it, not what was computed
  // on the log as read.
  PreprocessOptions o;
  o.detrend = Detrend::Mean;
  const auto withdrawn = d.setPreprocessed(std::make_shared<IdData>(log), o);
  ASSERT_EQ(withdrawn.size(), 1u);
  EXPECT_EQ(withdrawn.front(), "fit");
  EXPECT_TRUE(d.resultData("recursive").has_value());
  // Another log withdraws everything; a result of other data is refused.
  Provenance stale = d.dataProvenance();
  EXPECT_EQ(d.setLog(log, "/tmp/b.csv").size(), 1u);
  stale.sha256 = "zz";
  EXPECT_FALSE(d.recordResult("fit", stale));
}

}  // namespace
}  // namespace flexarm
