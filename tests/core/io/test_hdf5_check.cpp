// The walk of v7.3 (HDF5) .mat files before HDF5 opens them (core/io/hdf5_check.h): the files
// scripts/make_hostile_data.py writes are let through or refused by name, and every cut and
// every damaged byte of a good file ends in a sentence, never a crash, a hang or a pass of a
// file that points outside itself.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include "core/io/hdf5_check.h"

using namespace flexarm;

namespace {

std::string bytesOf(const std::string& name) {
  std::ifstream in(std::string(FLEXARM_TEST_DATA_DIR) + "/hostile/" + name, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

Hdf5Check walk(const std::string& bytes) {
  Hdf5Limits limits;
  limits.inflateBudget = 64u << 20;
  return checkHdf5File(bytes, limits);
}

}  // namespace

TEST(Hdf5Check, GoodFilesListTheirVariablesWithClassAndShape) {
  for (const char* f : {"v73_good.mat", "v73_good_latest.mat"}) {
    SCOPED_TRACE(f);
    const Hdf5Check c = walk(bytesOf(f));
    ASSERT_TRUE(c.ok) << c.problem;
    bool torque = false;
    for (const Hdf5Variable& v : c.variables)
      if (v.name == "torque_ref_nm") {
        torque = true;
        EXPECT_TRUE(v.dataset && v.numeric);
        EXPECT_EQ(v.matlabClass, "double");
        EXPECT_EQ(v.dims, (std::vector<std::uint64_t>{1, 400}));
      }
    EXPECT_TRUE(torque);
  }
  const Hdf5Check c = walk(bytesOf("v73_good.mat"));
  std::vector<std::string> skipped;
  for (const Hdf5Variable& v : c.variables)
    if (!v.numeric) skipped.push_back(v.name + ":" + v.matlabClass);
  EXPECT_EQ(skipped, (std::vector<std::string>{"notes:cell", "settings:struct"}));
}

TEST(Hdf5Check, HostileFilesAreRefusedByName) {
  const std::pair<const char*, const char*> cases[] = {
      {"v73_external_storage.mat", "/motor_angle_rad keeps its data in another file"},
      {"v73_external_link.mat", "/leak is an external link to another file"},
      {"v73_soft_link.mat", "/alias is a soft link"},
      {"v73_hard_link_cycle.mat", "a link cycle: /s/inner leads back"},
      {"v73_reference_cycle.mat", "a link cycle: /#refs#/a (reference 1) leads back"},
      {"v73_gzip_bomb.mat", "/zeros would take 128.0 MiB in memory uncompressed"},
      {"v73_plugin_filter.mat", "is compressed with filter 32000"},
      {"v73_truncated.mat", "points outside the file"},
      // Both made HDF5 loop forever (the first found by fuzz_mat73).
      {"v73_heap_no_progress.mat", "holds an object that reaches past its end or does not advance"},
      {"v73_free_list_cycle.mat", "has a free list that leaves the heap or runs in a circle"},
  };
  for (const auto& [file, message] : cases) {
    SCOPED_TRACE(file);
    const Hdf5Check c = walk(bytesOf(file));
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find(message), std::string::npos) << c.problem;
  }
}

TEST(Hdf5Check, EveryCutOfAGoodFileIsRefusedWithASentence) {
  const std::string good = bytesOf("v73_good_latest.mat");
  ASSERT_GT(good.size(), 4000u);
  // Every byte of the file belongs to something the walk reads (the last is data): no cut passes.
  for (std::size_t n = 0; n + 1 < good.size(); n += 61) {
    const Hdf5Check c = walk(good.substr(0, n));
    EXPECT_FALSE(c.ok) << n;
    EXPECT_FALSE(c.problem.empty()) << n;
  }
}

TEST(Hdf5Check, DamagedBytesEndInASentenceOrAFileThatStaysInside) {
  // Every byte of the structures (the first 4 KiB after the user block) set to 0xff in turn.
  const std::string good = bytesOf("v73_good.mat");
  int refused = 0;
  for (std::size_t i = 512; i < std::min<std::size_t>(good.size(), 4608); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(0xff);
    const Hdf5Check c = walk(bad);
    if (!c.ok) {
      ++refused;
      EXPECT_FALSE(c.problem.empty()) << i;
    }
  }
  EXPECT_GT(refused, 100);  // the walk reads what it checks
}

TEST(Hdf5Check, FuzzFoundFilesAreRefusedWithTheirReason) {
  // fuzz_mat73's findings: a file whose references were copied from a null pointer, and one
  // HDF5 looped on. Each is refused by the walk, naming what is wrong.
  const std::pair<const char*, const char*> cases[] = {
      {"mat73_empty_compact_references.mat", "/torque_ref_nm points outside the file"},
      {"mat73_timeout.mat", "reaches past its end or does not advance"},
  };
  for (const auto& [file, message] : cases) {
    SCOPED_TRACE(file);
    std::ifstream in(std::string(FLEXARM_TEST_DATA_DIR) + "/fuzz/" + file, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    ASSERT_GT(bytes.size(), 1000u);
    const Hdf5Check c = walk(bytes);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find(message), std::string::npos) << c.problem;
  }
}
