// The checks in front of every reader: well-formed files of each kind pass them and are read
// (level 4, 5 and compressed v7 .mat written by SciPy, a CSV log, a DaISy-like table); hostile
// files are refused from their stated sizes, devices and pipes before a byte is read, and
// text in another encoding by the name of that encoding.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/io/input_file.h"
#include "core/io/log_io.h"
#include "core/io/mat_check.h"

using namespace flexarm;
namespace fs = std::filesystem;

namespace {

std::string data(const std::string& rel) { return std::string(FLEXARM_TEST_DATA_DIR) + "/" + rel; }

std::string bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

TEST(InputChecks, WellFormedMatFilesOfEveryLevelAreRead) {
  for (const char* f : {"good/small_v4.mat", "good/small_v5.mat", "good/small_v7_compressed.mat"}) {
    SCOPED_TRACE(f);
    const MatCheck c = checkMatFile(bytesOf(data(f)), 1 << 20);
    EXPECT_TRUE(c.ok) << c.problem;
    LogReadResult r = readLog(data(f));
    if (!r.ok && r.needsSampleTime) {  // a file without time takes the sample time given
      LogReadOptions o;
      o.sampleTime = 0.001;
      r = readLog(data(f), o);
    }
    ASSERT_TRUE(r.ok) << r.error.toString();
    EXPECT_EQ(r.data.samples(), 64u);
    ASSERT_NE(r.data.input(), nullptr);
    EXPECT_NEAR(r.data.input()->values[1], std::sin(0.3), 1e-15);
  }
  EXPECT_EQ(checkMatFile(bytesOf(data("good/small_v4.mat")), 1 << 20).kind, MatKind::V4);
  EXPECT_EQ(checkMatFile(bytesOf(data("good/small_v5.mat")), 1 << 20).kind, MatKind::V5);
  // The level-4 file stores no time: it is refused with a sentence asking for the sample time.
  EXPECT_TRUE(readLog(data("good/small_v4.mat")).needsSampleTime);
  // The time vector of the level-5 file sets the sample time.
  EXPECT_NEAR(readLog(data("good/small_v5.mat")).data.sampleTime, 0.001, 1e-12);
}

TEST(InputChecks, HostileMatFilesAreRefusedFromTheirStatedSizes) {
  struct Case {
    const char* file;
    const char* needle;
  } cases[] = {
      {"hostile/mat_claims_2g_elements.mat", "claims 2147483647 elements but its data hold 6000"},
      {"hostile/mat_huge_name.mat", "an element claims 2147483640 bytes"},
      {"hostile/mat_compressed_claims_4g.mat", "claims to inflate to 4294967295 bytes"},
      {"hostile/mat_v4_claims_huge.mat", "damaged or cut short"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const MatCheck check = checkMatFile(bytesOf(data(c.file)), 1 << 20);
    EXPECT_FALSE(check.ok);
    EXPECT_NE(check.problem.find(c.needle), std::string::npos) << check.problem;
    const LogReadResult r = readLog(data(c.file));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.problem.find(c.needle), std::string::npos) << r.error.toString();
  }
  // Every prefix of a good file is refused or read, never trusted beyond its bytes.
  const std::string good = bytesOf(data("good/small_v7_compressed.mat"));
  for (std::size_t n = 0; n < good.size(); n += 7) {
    const MatCheck c = checkMatFile(std::string_view(good).substr(0, n), 1 << 20);
    if (!c.ok) {
      EXPECT_FALSE(c.problem.empty());
    }
  }
}

TEST(InputChecks, GoodTextLogsAreRead) {
  LogReadResult r = readLog(data("good/small_log.csv"));
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.samples(), 64u);
  EXPECT_TRUE(r.data.isClosedLoop());
  r = readLog(data("good/small_table.dat"));
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.channels.size(), 2u);
}

TEST(InputChecks, DevicesPipesAndDirectoriesAreRefusedBeforeReading) {
  std::string why;
  EXPECT_FALSE(checkInputFile("/dev/zero", 1 << 30, nullptr, &why));
  EXPECT_NE(why.find("is a character device, not a regular file"), std::string::npos) << why;
  FileBytes bytes;
  EXPECT_FALSE(readInputFile("/dev/urandom", 1 << 30, bytes, &why));
  EXPECT_NE(why.find("character device"), std::string::npos) << why;
  EXPECT_FALSE(readInputFile(FLEXARM_TEST_DATA_DIR, 1 << 30, bytes, &why));
  EXPECT_NE(why.find("is a directory"), std::string::npos) << why;
  // A named pipe with no writer: refused at once, not waited on.
  const fs::path dir = fs::temp_directory_path() / ("flexarm_fifo_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string fifo = (dir / "log.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const LogReadResult r = readLog(fifo);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.problem.find("is a pipe"), std::string::npos) << r.error.toString();
  fs::remove_all(dir);
  EXPECT_FALSE(readInputFile("/no/such/file.csv", 1 << 30, bytes, &why));
  EXPECT_EQ(why, "the file does not exist");
}

TEST(InputChecks, EncodingsAreNamed) {
  EXPECT_EQ(textEncodingProblem("time_s,u,y\n"), "");
  EXPECT_NE(textEncodingProblem("\xff\xfet\0i\0").find("UTF-16 text (it starts with a UTF-16 byte-order mark)"),
            std::string::npos);
  EXPECT_NE(textEncodingProblem(std::string("\xff\xfe\0\0", 4)).find("UTF-32"), std::string::npos);
  EXPECT_NE(textEncodingProblem("\xef\xbb\xbftime_s").find("UTF-8 byte-order mark (BOM)"), std::string::npos);
  EXPECT_NE(textEncodingProblem(std::string("t\0i\0m\0e\0", 8)).find("looks like UTF-16"), std::string::npos);
  EXPECT_NE(textEncodingProblem(std::string("time\0\0\0\x01\x02 data", 14)).find("binary data"),
            std::string::npos);
  for (const char* f : {"hostile/utf16le_bom.csv", "hostile/utf8_bom.csv"}) {
    const LogReadResult r = readLog(data(f));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.problem.find("byte-order mark"), std::string::npos) << r.error.toString();
  }
}

TEST(InputChecks, WritingRefusesDevicesAndKeepsTheOldFileOnFailure) {
  std::string why;
  EXPECT_FALSE(writeFileAtomically("/dev/full", "x", &why));
  EXPECT_NE(why.find("/dev/full is a character device"), std::string::npos) << why;
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  const fs::path dir = fs::temp_directory_path() / ("flexarm_write_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string target = (dir / "a.txt").string();
  ASSERT_TRUE(writeFileAtomically(target, "old", &why)) << why;
  // A producer whose output cannot be written (here: the target's folder is a file).
  EXPECT_FALSE(writeFileAtomically((dir / "a.txt" / "b.txt").string(), "new", &why));
  EXPECT_EQ(bytesOf(target), "old");
  // Piecewise writing gives the same bytes as one piece.
  ASSERT_TRUE(writeFileAtomically(
      target, [](const std::function<void(std::string_view)>& sink) {
        for (int i = 0; i < 1000; ++i) sink("0123456789");
      },
      &why));
  EXPECT_EQ(bytesOf(target).size(), 10000u);
  fs::remove_all(dir);
}

// Found by fuzz_table: comment lines ('%' followed by bytes that are no text) between rows of a
// table whose time column is irregular. The time-stamp report must pair each stamp with its
// line; it threw because it counted those lines differently from the reader.
TEST(InputChecks, IrregularTimeAmongCommentLinesIsRefusedWithASentence) {
  std::ifstream in(data("fuzz/table_comment_lines_irregular_time.bin"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1u);
  LogReadOptions o;  // as the fuzz target maps the first byte
  o.timeColumn = static_cast<unsigned char>(bytes[0]) % 3;
  o.inputColumn = o.timeColumn == 1 ? 2 : 1;
  o.outputColumn = o.timeColumn == 2 || o.timeColumn == 1 ? 3 : 2;
  LogReadResult r;
  ASSERT_NO_THROW(r = readTableText(std::string_view(bytes).substr(1), "fuzz.dat", o));
  if (!r.ok) {
    EXPECT_FALSE(r.error.problem.empty());
  } else {
    EXPECT_TRUE(r.data.isValid());
  }
  o.keepIrregularTime = true;
  ASSERT_NO_THROW(r = readTableText(std::string_view(bytes).substr(1), "fuzz.dat", o));
  if (r.ok) {
    EXPECT_EQ(r.data.sourceLines.size(), r.data.timeStamps.size());
  }
}

// fuzz_mat's findings: level-4 headers whose type reads right only in the byte order their
// M digit denies (matio then reads the name length the other way round: 1.8-1.9 GB for files
// of 129 and 136 bytes), one of them a sparse matrix of 16.5 million rows and no columns.
// Both are refused by the check before matio sees them.
TEST(InputChecks, Level4HeadersMatioWouldMisreadAreRefused) {
  const std::pair<const char*, std::size_t> files[] = {{"fuzz/mat4_sparse_no_columns.mat", 136},
                                                       {"fuzz/mat4_byte_order_mixed.mat", 129}};
  for (const auto& [file, size] : files) {
    SCOPED_TRACE(file);
    const std::string bytes = bytesOf(data(file));
    ASSERT_EQ(bytes.size(), size);
    const MatCheck c = checkMatFile(bytes, 1 << 20);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find("states little-endian numbers but its header is written the other way"),
              std::string::npos)
        << c.problem;
    const LogReadResult r = readLog(data(file));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.toString().find("little-endian"), std::string::npos) << r.error.toString();
  }
}
