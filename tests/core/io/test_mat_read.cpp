// Reading .mat files: every numeric class FlexArm reads arrives as the same doubles whether
// the variables are rows or columns, compressed or not, level 5 or level 4; a non-finite
// element, a matrix and a text variable are refused with a sentence naming the variable.
#include <gtest/gtest.h>
#include <matio.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "core/io/log_io.h"

using namespace flexarm;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
  fs::path p = fs::temp_directory_path() / ("flexarm_mat_read_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

// Writes variables of n elements: time_s, u (double), y (single), and the int16 and int32
// channels k and j, as rows or columns.
void writeMat(const fs::path& p, mat_ft version, matio_compression compression, bool rows,
              std::size_t n) {
  mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, version);
  ASSERT_NE(mat, nullptr);
  std::size_t dims[2] = {rows ? 1 : n, rows ? n : 1};
  std::vector<double> t(n), u(n);
  std::vector<float> y(n);
  std::vector<std::int16_t> k(n);
  std::vector<std::int32_t> j(n);
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = 0.001 * static_cast<double>(i);
    u[i] = std::sin(0.3 * static_cast<double>(i)) + 1e-9 * static_cast<double>(i);
    y[i] = static_cast<float>(0.25 * static_cast<double>(i));
    k[i] = static_cast<std::int16_t>(static_cast<int>(i % 700) - 350);
    j[i] = static_cast<std::int32_t>(i * 1000);
  }
  const auto put = [&](const char* name, matio_classes c, matio_types type, void* data) {
    matvar_t* var = Mat_VarCreate(name, c, type, 2, dims, data, 0);
    ASSERT_NE(var, nullptr);
    EXPECT_EQ(Mat_VarWrite(mat, var, compression), 0);
    Mat_VarFree(var);
  };
  put("time_s", MAT_C_DOUBLE, MAT_T_DOUBLE, t.data());
  put("u", MAT_C_DOUBLE, MAT_T_DOUBLE, u.data());
  if (version != MAT_FT_MAT4) {  // level 4 holds doubles only
    put("y", MAT_C_SINGLE, MAT_T_SINGLE, y.data());
    put("k", MAT_C_INT16, MAT_T_INT16, k.data());
    put("j", MAT_C_INT32, MAT_T_INT32, j.data());
  } else {
    std::vector<double> yd(y.begin(), y.end());
    put("y", MAT_C_DOUBLE, MAT_T_DOUBLE, yd.data());
  }
  Mat_Close(mat);
}

}  // namespace

TEST(MatRead, EveryClassLayoutAndCompressionGivesTheSameDoubles) {
  const std::size_t n = 3001;
  struct Layout {
    mat_ft version;
    matio_compression compression;
    bool rows;
  };
  const Layout layouts[] = {{MAT_FT_MAT5, MAT_COMPRESSION_NONE, false},
                            {MAT_FT_MAT5, MAT_COMPRESSION_NONE, true},
                            {MAT_FT_MAT5, MAT_COMPRESSION_ZLIB, false},
                            {MAT_FT_MAT4, MAT_COMPRESSION_NONE, false}};
  int index = 0;
  for (const Layout& l : layouts) {
    SCOPED_TRACE("layout " + std::to_string(index));
    const fs::path p = tempDir() / ("layout" + std::to_string(index++) + ".mat");
    writeMat(p, l.version, l.compression, l.rows, n);
    const LogReadResult r = readLog(p.string());
    ASSERT_TRUE(r.ok) << r.error.toString();
    ASSERT_EQ(r.data.samples(), n);
    EXPECT_NEAR(r.data.sampleTime, 0.001, 1e-12);
    const Channel* u = r.data.channel("u");
    const Channel* y = r.data.channel("y");
    ASSERT_TRUE(u && y);
    EXPECT_EQ(r.data.input(), u);
    EXPECT_EQ(r.data.output(), y);
    EXPECT_EQ(u->values[1234], std::sin(0.3 * 1234) + 1e-9 * 1234);
    EXPECT_EQ(y->values[3000], 750.0);
    if (l.version != MAT_FT_MAT4) {
      const Channel* k = r.data.channel("k");
      const Channel* j = r.data.channel("j");
      ASSERT_TRUE(k && j);
      EXPECT_EQ(k->values[0], -350.0);
      EXPECT_EQ(k->values[2999], 2999.0 - 2800.0 - 350.0);
      EXPECT_EQ(j->values[3000], 3000000.0);
    }
  }
  fs::remove_all(tempDir());
}

// A large level-5 file is checked on the parts the check reads and its numbers are read
// straight from the file (over several threads for a long double variable): every element
// arrives, across every block border.
TEST(MatRead, LargeFileReadsEveryElementStraightFromTheFile) {
  const std::size_t n = 600001;  // 4.8 MB per double variable
  const fs::path p = tempDir() / "large.mat";
  writeMat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE, false, n);
  const LogReadResult r = readLog(p.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  ASSERT_EQ(r.data.samples(), n);
  const Channel* u = r.data.channel("u");
  const Channel* y = r.data.channel("y");
  const Channel* k = r.data.channel("k");
  const Channel* j = r.data.channel("j");
  ASSERT_TRUE(u && y && k && j);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < n; ++i) {
    wrong += u->values[i] != std::sin(0.3 * static_cast<double>(i)) + 1e-9 * static_cast<double>(i);
    wrong += y->values[i] != static_cast<double>(static_cast<float>(0.25 * static_cast<double>(i)));
    wrong += k->values[i] != static_cast<double>(static_cast<int>(i % 700) - 350);
    wrong += j->values[i] != static_cast<double>(static_cast<std::int32_t>(i * 1000));
  }
  EXPECT_EQ(wrong, 0u);
  fs::remove_all(tempDir());
}

TEST(MatRead, NonFiniteElementsMatricesAndTextAreRefusedByName) {
  const fs::path p = tempDir() / "refused.mat";
  const std::size_t n = 100;
  std::vector<double> t(n), u(n), y(n), grid(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = 0.01 * static_cast<double>(i);
    u[i] = 1.0;
    y[i] = static_cast<double>(i);
  }
  y[57] = std::numeric_limits<double>::infinity();
  const auto write = [&](const char* yName, const std::vector<double>& yValues) {
    mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, MAT_FT_MAT5);
    ASSERT_NE(mat, nullptr);
    std::size_t column[2] = {n, 1}, matrix[2] = {n, 2}, text[2] = {1, 5};
    char word[] = "hello";
    const auto put = [&](const char* name, matio_classes c, matio_types type, std::size_t* dims,
                         const void* data) {
      matvar_t* var = Mat_VarCreate(name, c, type, 2, dims, const_cast<void*>(data), 0);
      ASSERT_NE(var, nullptr);
      Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
      Mat_VarFree(var);
    };
    put("time_s", MAT_C_DOUBLE, MAT_T_DOUBLE, column, t.data());
    put("u", MAT_C_DOUBLE, MAT_T_DOUBLE, column, u.data());
    put(yName, MAT_C_DOUBLE, MAT_T_DOUBLE, column, yValues.data());
    put("grid", MAT_C_DOUBLE, MAT_T_DOUBLE, matrix, grid.data());
    put("note", MAT_C_CHAR, MAT_T_UINT8, text, word);
    Mat_Close(mat);
  };
  write("y", y);
  LogReadResult r = readLog(p.string());
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.columnName, "y");
  EXPECT_NE(r.error.problem.find("element 58 is not a finite number"), std::string::npos)
      << r.error.problem;

  LogReadOptions o;
  o.mapping.output = "grid";
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.columnName, "grid");
  EXPECT_NE(r.error.problem.find("is a 100 x 2 array: name a row or a column, e.g. grid(1,:)"), std::string::npos) << r.error.problem;

  o.mapping.output = "note";
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.columnName, "note");
  EXPECT_NE(r.error.problem.find("is a 1 x 5 char array, not numbers"), std::string::npos) << r.error.problem;

  // With a finite y the matrix and the text are not channels, and the rest reads.
  y[57] = 57.0;
  write("y", y);
  r = readLog(p.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.channels.size(), 2u);
  EXPECT_EQ(r.data.output()->values, y);
  fs::remove_all(tempDir());
}

// MATLAB stores a double array whose values fit a smaller integer type in that type; the
// reader converts every stored type to the variable's class.
TEST(MatRead, DoublesStoredAsSmallerTypesReadAsTheirValues) {
  const fs::path p = tempDir() / "stored.mat";
  const std::size_t n = 300;
  std::vector<std::uint8_t> t8(n);
  std::vector<std::int16_t> u16(n);
  std::vector<float> yf(n);
  for (std::size_t i = 0; i < n; ++i) {
    t8[i] = static_cast<std::uint8_t>(i % 256);
    u16[i] = static_cast<std::int16_t>(static_cast<int>(i) * 100 - 15000);
    yf[i] = 0.1f * static_cast<float>(i);
  }
  for (auto compression : {MAT_COMPRESSION_NONE, MAT_COMPRESSION_ZLIB}) {
    mat_t* mat = Mat_CreateVer(p.string().c_str(), nullptr, MAT_FT_MAT5);
    ASSERT_NE(mat, nullptr);
    std::size_t dims[2] = {n, 1};
    const auto put = [&](const char* name, matio_types type, void* data) {
      matvar_t* var = Mat_VarCreate(name, MAT_C_DOUBLE, type, 2, dims, data, 0);
      ASSERT_NE(var, nullptr);
      EXPECT_EQ(Mat_VarWrite(mat, var, compression), 0);
      Mat_VarFree(var);
    };
    put("u", MAT_T_INT16, u16.data());
    put("y", MAT_T_SINGLE, yf.data());
    put("k", MAT_T_UINT8, t8.data());
    Mat_Close(mat);
    LogReadOptions o;
    o.sampleTime = 0.001;  // the file stores no time
    const LogReadResult r = readLog(p.string(), o);
    ASSERT_TRUE(r.ok) << r.error.toString();
    ASSERT_EQ(r.data.samples(), n);
    EXPECT_EQ(r.data.channel("u")->values[0], -15000.0);
    EXPECT_EQ(r.data.channel("u")->values[299], 14900.0);
    EXPECT_EQ(r.data.channel("y")->values[7], static_cast<double>(0.7f));
    ASSERT_TRUE(r.data.channel("k"));
    EXPECT_EQ(r.data.channel("k")->values[257], 1.0);
  }
  fs::remove_all(tempDir());
}

// A level-5 file written on a big-endian machine (built here byte by byte: header 'MI', then
// the miMATRIX elements of u and y) reads as the same numbers.
TEST(MatRead, BigEndianLevel5FileReadsTheSameNumbers) {
  std::string file(128, ' ');
  file[124] = 1;  // version 0x0100, most significant byte first
  file[125] = 0;
  file[126] = 'M';
  file[127] = 'I';
  const auto u32 = [](std::string& s, std::uint32_t v) {
    for (int b = 3; b >= 0; --b) s.push_back(static_cast<char>((v >> (8 * b)) & 0xff));
  };
  const auto variable = [&](const std::string& name, const std::vector<double>& values) {
    std::string body;
    u32(body, 6);  // miUINT32 array flags: class double
    u32(body, 8);
    u32(body, 6);
    u32(body, 0);
    u32(body, 5);  // miINT32 dimensions: n x 1
    u32(body, 8);
    u32(body, static_cast<std::uint32_t>(values.size()));
    u32(body, 1);
    u32(body, 1);  // miINT8 name, padded to 8 bytes
    u32(body, static_cast<std::uint32_t>(name.size()));
    body += name;
    body.append((8 - name.size() % 8) % 8, '\0');
    u32(body, 9);  // miDOUBLE data
    u32(body, static_cast<std::uint32_t>(8 * values.size()));
    for (double v : values) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, 8);
      u32(body, static_cast<std::uint32_t>(bits >> 32));
      u32(body, static_cast<std::uint32_t>(bits & 0xffffffffu));
    }
    u32(file, 14);  // miMATRIX
    u32(file, static_cast<std::uint32_t>(body.size()));
    file += body;
  };
  variable("u", {1.5, -2.25, 3e-7, 4.0});
  variable("y", {0.1, 0.2, 0.3, 1e300});
  const fs::path p = tempDir() / "big_endian.mat";
  {
    std::ofstream out(p, std::ios::binary);
    out << file;
  }
  LogReadOptions o;
  o.sampleTime = 0.001;  // the file stores no time
  const LogReadResult r = readLog(p.string(), o);
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.channel("u")->values, (std::vector<double>{1.5, -2.25, 3e-7, 4.0}));
  EXPECT_EQ(r.data.channel("y")->values, (std::vector<double>{0.1, 0.2, 0.3, 1e300}));
  fs::remove_all(tempDir());
}
