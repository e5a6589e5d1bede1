// The one writer of every file (writeFileAtomically, core/io/log_io.h): it never follows or
// replaces a link, makes its temporary file afresh under a name no one can plant a link at,
// and leaves nothing behind.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/io/log_io.h"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexarm_write_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(AtomicWrite, ALinkAtTheTargetIsRefusedAndItsTargetKept) {
  const fs::path d = scratch("link");
  { std::ofstream(d / "victim") << "keep"; }
  fs::create_symlink(d / "victim", d / "out.csv");
  std::string why;
  EXPECT_FALSE(flexarm::writeFileAtomically((d / "out.csv").string(), "new", &why));
  EXPECT_NE(why.find("out.csv is a symbolic link; FlexArm writes only regular files"), std::string::npos) << why;
  EXPECT_EQ(text(d / "victim"), "keep");
  EXPECT_TRUE(fs::is_symlink(d / "out.csv"));
}

TEST(AtomicWrite, LinksPlantedAtTheOldTemporaryNamesAreNotFollowed) {
  const fs::path d = scratch("planted");
  { std::ofstream(d / "victim") << "keep"; }
  for (const char* name : {"report.pdf.part", "report.pdf.tmp-0", "report.pdf.tmp-1-0"})
    fs::create_symlink(d / "victim", d / name);
  std::string why;
  ASSERT_TRUE(flexarm::writeFileAtomically((d / "report.pdf").string(), "%PDF", &why)) << why;
  EXPECT_EQ(text(d / "report.pdf"), "%PDF");
  EXPECT_EQ(text(d / "victim"), "keep");
  // Nothing left behind but what was there.
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(d)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"victim", "report.pdf", "report.pdf.part", "report.pdf.tmp-0",
                                          "report.pdf.tmp-1-0"}));
}

TEST(AtomicWrite, TemporaryNamesDifferFromWriteToWrite) {
  // The name is not derived from the process or a counter: two writers in one process and
  // folder never meet, and nothing can be planted in advance.
  const fs::path d = scratch("names");
  std::set<std::string> seen;
  for (int k = 0; k < 20; ++k) {
    std::string name;
    ASSERT_TRUE(flexarm::writeFileAtomically(
        (d / "x.csv").string(),
        [&](const std::function<void(std::string_view)>& sink) {
          for (const auto& e : fs::directory_iterator(d))
            if (e.path().filename().string().rfind(".x.csv.tmp-", 0) == 0) name = e.path().filename().string();
          sink("1");
        },
        nullptr));
    EXPECT_EQ(name.size(), std::string(".x.csv.tmp-").size() + 16) << name;
    EXPECT_TRUE(seen.insert(name).second) << name;
  }
}
