// Reading a 2 kHz robot log: FlexArm's reader against pandas.read_csv (CSV) and
// scipy.io.loadmat (.mat) on the same files, at 1x, 4x and 16x data (16x is the seed's
// ten-minute log, 92 MB of CSV). Agreement: sample count and every column's sum of squares.
#include <filesystem>

#include "bench_common.h"
#include "bench_data.h"
#include "core/io/log_io.h"

using namespace flexarm;
using namespace flexarm::bench;

namespace {

// Sum of squares of every channel, in the order torque, angle, reference.
std::vector<double> columnSums(const IdData& d) {
  std::vector<double> s;
  for (const char* name : {columns::kTorqueRef, columns::kMotorAngle, columns::kAngleRef}) {
    const Channel* c = d.channel(name);
    double sum = 0.0;
    if (c)
      for (double v : c->values) sum += v * v;
    s.push_back(c ? sum : NAN);
  }
  return s;
}

// Agreement of FlexArm's read with the peer's: same sample count, column sums equal.
void compare(Row& row, const IdData& mine, const Json& peer) {
  const auto sums = columnSums(mine);
  const auto theirs = peer.value("sums", std::vector<double>{});
  double worst = 0.0;
  bool same = theirs.size() == sums.size() && peer.value("samples", 0L) == static_cast<long>(mine.samples());
  for (std::size_t i = 0; same && i < sums.size(); ++i) worst = std::max(worst, relDiff(sums[i], theirs[i]));
  row.agree = same && worst < 1e-9;
  std::ostringstream s;
  s.precision(2);
  s << "values: " << mine.samples() << " samples, sums of squares differ by " << worst;
  row.agreement = same ? s.str() : "values: different sample counts or columns";
}

}  // namespace

int main() {
  TempDir dir("flexarm-bench-log");
  std::vector<std::string> csv;
  for (int scale : {1, 4, 16}) {
    csv.push_back(dir.file("log" + std::to_string(scale) + "x.csv"));
    if (!writeFlexArmCsv(syntheticLog(kLogUnit * scale), csv.back())) return 1;
  }
  const std::string mat = dir.file("log16x.mat");
  // The peer reads every CSV with pandas, writes the largest as .mat and reads it back.
  // Nine repeats a side: the first reads of a process pay for fresh memory, and the median
  // of nine is not moved by them.
  constexpr int kRepeats = 9;
  std::string args = std::to_string(repeats(kRepeats)) + " " + mat;
  for (const auto& f : csv) args += " " + f;
  std::string why;
  const auto peer = runPeer(python("peer_log.py", args), &why);

  for (std::size_t i = 0; i < csv.size(); ++i) {
    const int scale = 1 << (2 * i);
    LogReadResult res;
    Row row;
    row.group = "log";
    row.task = "read CSV log";
    row.scale = scale;
    // A large log is read by a thread per core, each its part of the file; the CPU clock
    // (FLEXARM_BENCH_CLOCK=cpu) counts the time of every thread, more than the wall clock
    // of an idle machine. As many repeats as the peer's (peer_log.py), median of them.
    row.flexarmSeconds = medianSeconds(repeats(kRepeats), [&] { res = readLog(csv[i]); });
    if (!res.ok) {
      std::cerr << "bench_log: " << res.error.toString() << "\n";
      return 1;
    }
    const double bytes = static_cast<double>(std::filesystem::file_size(csv[i]));
    const double mbPerSecond = bytes / 1e6 / row.flexarmSeconds;
    char rate[64];
    std::snprintf(rate, sizeof rate, ", FlexArm %.0f MB/s", mbPerSecond);
    row.size = megabytes(bytes) + ", " + std::to_string(res.data.samples() / 1000) + "k x 4" + rate;
    row.extra["bytes"] = bytes;
    row.extra["flexarm_mb_s"] = mbPerSecond;
    row.peer = "pandas.read_csv";
    const Json p = peerResult(peer, "csv" + std::to_string(i));
    if (!p.is_null()) {
      row.peerSeconds = p["seconds"].get<double>();
      compare(row, res.data, p);
    } else {
      row.extra["note"] = why;
    }
    emit(row);
  }

  Row row;
  row.group = "log";
  row.task = "read .mat log";
  row.peer = "scipy.io.loadmat";
  const Json p = peerResult(peer, "mat");
  if (p.is_null() || !std::filesystem::exists(mat)) {
    std::cerr << "bench_log: the peer wrote no .mat file (" << why << ")\n";
    return 1;
  }
  LogReadResult res;
  row.flexarmSeconds = medianSeconds(repeats(kRepeats), [&] { res = readLog(mat); });
  if (!res.ok) {
    std::cerr << "bench_log: " << res.error.toString() << "\n";
    return 1;
  }
  row.size = megabytes(static_cast<double>(std::filesystem::file_size(mat))) + ", " +
             std::to_string(res.data.samples() / 1000) + "k x 4";
  row.peerSeconds = p["seconds"].get<double>();
  compare(row, res.data, p);
  emit(row);
  return 0;
}
