#include "core/fleet/manifest.h"

#include <gtest/gtest.h>

namespace flexarm {
namespace {

const char* kIssueExample =
    "# flexarm-fleet: 1\n"
    "robot,axis,time,log,temperature_c,role\n"
    "R01,1,2026-03-01T06:00:00Z,R01/ax1/2026-03-01.csv,24.5,reference\n"
    "R01,1,2026-03-02T06:00:00Z,R01/ax1/2026-03-02.csv,31.0,\n";

TEST(FleetManifest, ReadsTheDocumentedExample) {
  ManifestError e;
  const auto m = parseFleetManifest(kIssueExample, "/plant/fleet.csv", &e);
  ASSERT_TRUE(m) << e.toString();
  ASSERT_EQ(m->entries.size(), 2u);
  ASSERT_EQ(m->axes.size(), 1u);
  const auto& a = m->axes[0];
  EXPECT_EQ(a.key(), "R01/1");
  EXPECT_EQ(a.referenceEntry, 0u);
  EXPECT_EQ(m->entries[1].path, "/plant/R01/ax1/2026-03-02.csv");  // relative to the manifest
  ASSERT_TRUE(m->entries[1].temperatureC);
  EXPECT_DOUBLE_EQ(*m->entries[1].temperatureC, 31.0);
  // 2026-03-01 is 20513 days after 1970-01-01; 06:00 a quarter day.
  EXPECT_DOUBLE_EQ(m->entries[0].day, 20513.25);
  EXPECT_EQ(m->entries[1].day - m->entries[0].day, 1.0);
}

TEST(FleetManifest, WithoutAReferenceTheEarliestLogIsOneAndColumnsMayBeReordered) {
  const char* text =
      "# flexarm-fleet: 1\n"
      "log,time,axis,robot\n"
      "b.csv,2026-03-05T06:00,2,R07\n"
      "a.csv,2026-03-04,2,R07\n"
      "/abs/c.csv,2026-03-06T06:00:00Z,1,R07\n";
  ManifestError e;
  EXPECT_FALSE(parseFleetManifest(text, "fleet.csv", &e));  // /abs lies outside the folder
  EXPECT_EQ(e.line, 5);
  ManifestReadOptions anywhere;
  anywhere.allowLogsOutside = true;
  const auto m = parseFleetManifest(text, "fleet.csv", &e, anywhere);
  ASSERT_TRUE(m) << e.toString();
  ASSERT_EQ(m->axes.size(), 2u);
  EXPECT_EQ(m->axes[0].axis, 1);
  const auto* two = m->axis("R07", 2);
  ASSERT_NE(two, nullptr);
  EXPECT_EQ(m->entries[two->referenceEntry].log, "a.csv");
  EXPECT_EQ(m->entries[two->entries.front()].log, "a.csv");  // time order
  EXPECT_EQ(m->entries[2].path, "/abs/c.csv");
  EXPECT_FALSE(m->entries[0].temperatureC);
}

void expectRefused(const std::string& body, int line, const std::string& column, const std::string& words) {
  ManifestError e;
  EXPECT_FALSE(parseFleetManifest(body, "plant.csv", &e)) << body;
  EXPECT_EQ(e.line, line) << e.toString();
  EXPECT_EQ(e.column, column) << e.toString();
  EXPECT_NE(e.toString().find(words), std::string::npos) << e.toString();
  EXPECT_EQ(e.toString().rfind("plant.csv:", 0), 0u) << e.toString();
}

TEST(FleetManifest, RefusesBadInputNamingLineColumnAndProblem) {
  const std::string head = "# flexarm-fleet: 1\nrobot,axis,time,log,temperature_c,role\n";
  expectRefused("robot,axis,time,log\nR1,1,2026-03-01,a.csv\n", 1, "", "# flexarm-fleet: 1");
  expectRefused("# flexarm-fleet: 2\n", 1, "", "version '2'");
  expectRefused("# flexarm-fleet: 1\nrobot,axis,when,log\n", 2, "when", "unknown column");
  expectRefused("# flexarm-fleet: 1\nrobot,axis,log\n", 2, "time", "lacks this column");
  expectRefused(head + "R1,1,2026-02-29T06:00:00Z,a.csv,20,\n", 3, "time", "'2026-02-29T06:00:00Z' is not");
  expectRefused(head + "R1,0,2026-03-01,a.csv,20,\n", 3, "axis", "'0' is not an axis");
  expectRefused(head + "R1,1,2026-03-01,a.csv,warm,\n", 3, "temperature_c", "'warm'");
  expectRefused(head + "R1,1,2026-03-01,a.csv,20,healthy\n", 3, "role", "'healthy' is not a role");
  expectRefused(head + "R1,1,2026-03-01,a.csv,20\n", 3, "", "5 fields, the header has 6");
  expectRefused(head + "R1,1,2026-03-01,a.csv,,\nR1,1,2026-03-01,b.csv,,\n", 4, "time", "two logs at");
  expectRefused(head + "R1,1,2026-03-01,a.csv,,reference\nR1,1,2026-03-02,b.csv,,reference\n", 4, "role",
                "already has its reference on line 3");
}

TEST(FleetManifest, DaysAndIsoTimesRoundTrip) {
  EXPECT_EQ(*parseIsoDay("1970-01-02T00:00:00Z"), 1.0);
  EXPECT_EQ(*parseIsoDay("2024-02-29T18:00:00Z"), 19782.75);  // a leap day
  EXPECT_FALSE(parseIsoDay("2023-02-29"));
  EXPECT_FALSE(parseIsoDay("2026-03-01T24:00:00Z"));
  EXPECT_FALSE(parseIsoDay("2026-3-01"));
  for (double day : {0.0, 20513.25, 19782.75, 20513.0 + 13.0 / 24.0 + 7.0 / 1440.0})
    EXPECT_NEAR(*parseIsoDay(isoFromDay(day)), day, 1e-9) << isoFromDay(day);
  EXPECT_EQ(isoFromDay(20513.25), "2026-03-01T06:00:00Z");
}

TEST(FleetManifest, WrittenManifestReadsBack) {
  ManifestError e;
  const auto m = parseFleetManifest(kIssueExample, "fleet.csv", &e);
  ASSERT_TRUE(m);
  const auto again = parseFleetManifest(fleetManifestText(m->entries), "fleet.csv", &e);
  ASSERT_TRUE(again) << e.toString();
  ASSERT_EQ(again->entries.size(), 2u);
  EXPECT_TRUE(again->entries[0].reference);
  EXPECT_EQ(*again->entries[0].temperatureC, 24.5);
  EXPECT_EQ(again->entries[1].day, m->entries[1].day);
}

}  // namespace
}  // namespace flexarm
