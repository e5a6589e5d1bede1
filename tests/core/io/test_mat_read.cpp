// Reading .mat files: every numeric class FlexArm reads arrives as the same doubles whether
// the variables are rows or columns, compressed or not, level 5 or level 4; a non-finite
// element, a matrix and a text variable are refused with a sentence naming the variable.
#include <gtest/gtest.h>
#include <matio.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
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
  o.outputVariable = "grid";
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.columnName, "grid");
  EXPECT_NE(r.error.problem.find("must be a real vector"), std::string::npos) << r.error.problem;

  o.outputVariable = "note";
  r = readLog(p.string(), o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.columnName, "note");
  EXPECT_NE(r.error.problem.find("not a numeric vector"), std::string::npos) << r.error.problem;

  // With a finite y the matrix and the text are not channels, and the rest reads.
  y[57] = 57.0;
  write("y", y);
  r = readLog(p.string());
  ASSERT_TRUE(r.ok) << r.error.toString();
  EXPECT_EQ(r.data.channels.size(), 2u);
  EXPECT_EQ(r.data.output()->values, y);
  fs::remove_all(tempDir());
}
