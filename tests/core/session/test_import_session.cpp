// A log imported with a mapping (the KUKA KR300 axis 2: MATLAB expressions, units, the arm
// side, the gear ratio) is read the same way by a session: the mapping survives the session's
// text, prepareSession reads the same numbers, and the reading is part of the provenance, so
// results on the same file read another way are told apart.
#include <gtest/gtest.h>

#include "core/session/provenance.h"
#include "core/session/replay.h"
#include "core/session/session.h"
#include "core/session/sha256.h"

using namespace flexarm;

namespace {

const std::string kKuka = std::string(FLEXARM_SAMPLE_DIR) + "/kuka_kr300/rec_B_data.mat";

LogReadOptions axisTwo() {
  LogReadOptions o;
  LogMapping& m = o.mapping;
  m.time = "rec.time_cont";
  m.input = "rec.act_torque_abs_nm(2,:)";
  m.output = "rec.act_pos_mot_deg(2,:)";
  m.arm = "rec.act_pos_se_deg(2,:)";
  m.reference = "rec.ref_pos_deg(2,:)";
  m.outputUnit = SignalUnit::Deg;
  m.armUnit = SignalUnit::Deg;
  m.outputSide = EncoderSide::Arm;
  m.gearRatio = "1/267.43";
  m.inputScale = 1.5;
  return o;
}

}  // namespace

TEST(ImportSession, MappingSurvivesTheSessionAndReplaysTheSameNumbers) {
  Session s;
  LogReference log;
  log.name = "log";
  log.path = kKuka;
  log.sha256 = sha256OfFile(kKuka, nullptr).value_or("");
  log.read = axisTwo();
  s.logs.push_back(log);
  const std::string text = toJsonText(s);
  EXPECT_NE(text.find("\"gear_ratio\": \"1/267.43\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"output_side\": \"arm\""), std::string::npos) << text;
  const SessionParseResult back = parseSession(text);
  ASSERT_TRUE(back.ok) << back.message;
  EXPECT_TRUE(back.session.logs[0].read.mapping == axisTwo().mapping);
  EXPECT_EQ(toJsonText(back.session), text);

  const PreparedSession prepared = prepareSession(back.session, "/tmp/any.json");
  ASSERT_TRUE(prepared.ok) << prepared.message;
  const LogReadResult direct = readLog(kKuka, axisTwo());
  ASSERT_TRUE(direct.ok) << direct.error.toString();
  const IdData& replayed = prepared.logs.front().data;
  ASSERT_TRUE(replayed.channel(columns::kMotorAngle));
  EXPECT_EQ(replayed.channel(columns::kMotorAngle)->values, direct.data.channel(columns::kMotorAngle)->values);
  EXPECT_EQ(replayed.channel(columns::kTorqueRef)->values, direct.data.channel(columns::kTorqueRef)->values);
  EXPECT_EQ(replayed.meta("gear_ratio"), direct.data.meta("gear_ratio"));
  EXPECT_TRUE(replayed.isClosedLoop());

  // The report's Data section says how the log was read.
  const ReplayResult replayed2 = replaySession(back.session, "/tmp/any.json");
  ASSERT_EQ(replayed2.termination, Termination::Converged) << replayed2.message;
  bool said = false;
  for (const auto& section : replayed2.report.sections)
    for (const auto& p : section.paragraphs)
      said = said || p.find("Log 'log' read with time = rec.time_cont; input torque_ref_nm = 1.5 x "
                            "rec.act_torque_abs_nm(2,:)") != std::string::npos;
  EXPECT_TRUE(said);

  // A session whose mapping is damaged is refused with the key named.
  std::string bad = text;
  bad.replace(bad.find("\"arm\""), 5, "\"elbow\"");
  const SessionParseResult refused = parseSession(bad);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.message.find("output_side"), std::string::npos) << refused.message;
}

TEST(ImportSession, TheReadingIsPartOfTheProvenance) {
  Session s;
  LogReference log;
  log.name = "log";
  log.path = kKuka;
  log.read = axisTwo();
  s.logs.push_back(log);
  const Provenance a = sessionDataProvenance(s, kKuka, "abc");
  ASSERT_FALSE(a.reading.empty());
  EXPECT_NE(longDescription(a).find("read with"), std::string::npos);
  EXPECT_NE(longDescription(a).find("rec.act_pos_mot_deg(2,:) in deg on the arm side, times 267.43"), std::string::npos)
      << longDescription(a);
  // The same file read as axis 3 is other data.
  s.logs[0].read.mapping.output = "rec.act_pos_mot_deg(3,:)";
  const Provenance b = sessionDataProvenance(s, kKuka, "abc");
  EXPECT_FALSE(sameData(a, b));
  EXPECT_NE(dataMismatch(a, b).find("read or preprocessed differently"), std::string::npos);
  // And the record survives JSON.
  std::string why;
  const auto back = provenanceFromJson(provenanceToJson(a), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->reading, a.reading);
  // A FlexArm log read as it is has no reading recorded (sessions written before stay equal).
  s.logs[0].read = LogReadOptions{};
  EXPECT_TRUE(sessionDataProvenance(s, kKuka, "abc").reading.empty());
  EXPECT_FALSE(provenanceToJson(sessionDataProvenance(s, kKuka, "abc")).contains("reading"));
}
