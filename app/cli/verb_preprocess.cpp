// flexarm preprocess LOG --decimate N [--detrend] --out OUT.csv
#include <chrono>
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "core/io/ranges.h"
#include "core/signal/preprocess.h"

namespace flexarm::cli {
namespace {

const char* kPreprocessHelp =
    "Usage: flexarm preprocess LOG --out OUT.csv [options] [--json]\n\n"
    "Prepares a log for identification as in the seed's Section 5.2 and writes a FlexArm CSV\n"
    "log. Steps, in this order: differentiate, cut to a range, decimate, detrend.\n\n"
    "  --out FILE            the FlexArm CSV log to write (required)\n"
    "  --differentiate       add motor_velocity_rad_s = d/dt motor_angle_rad as the output\n"
    "  --range A:B           keep only the samples from A to B seconds\n"
    "  --decimate N          keep every N-th sample after the anti-alias filter (default 1)\n"
    "  --filter fir|chebyshev|none\n"
    "                        anti-alias filter: linear-phase FIR with >= 80 dB stopband from\n"
    "                        the new Nyquist frequency (default), order-8 Chebyshev I run\n"
    "                        forward and backward, or none (aliasing)\n"
    "  --detrend             remove the means of input and output\n"
    "  --detrend-linear      remove linear trends of input and output\n"
    "  --json                print a JSON summary of the result\n";

}  // namespace

int runPreprocess(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = logReadOptionNames();
  for (const char* v : {"out", "decimate", "filter", "range"}) valued.push_back(v);
  ArgParser args({"json", "help", "detrend", "detrend-linear", "differentiate"}, valued);
  if (!args.parse(argv)) {
    err << "flexarm preprocess: " << args.error() << "\n" << kPreprocessHelp;
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kPreprocessHelp << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  if (args.positional().size() != 1) {
    err << "flexarm preprocess: expected exactly one LOG\n" << kPreprocessHelp;
    return kExitUsage;
  }
  auto outPath = args.value("out");
  if (!outPath) {
    err << "flexarm preprocess: --out OUT.csv is required\n";
    return kExitUsage;
  }
  PreprocessOptions p;
  if (!args.integer("decimate", p.decimation.factor, 1, 1000000)) {
    err << "flexarm preprocess: " << args.error() << "\n";
    return kExitUsage;
  }
  if (auto f = args.value("filter")) {
    auto parsed = antiAliasFilterFromString(*f);
    if (!parsed) {
      err << "flexarm preprocess: --filter must be fir, chebyshev or none, not '" << *f << "'\n";
      return kExitUsage;
    }
    p.decimation.filter = *parsed;
  }
  if (args.flag("detrend") && args.flag("detrend-linear")) {
    err << "flexarm preprocess: give --detrend or --detrend-linear, not both\n";
    return kExitUsage;
  }
  if (args.flag("detrend")) p.detrend = Detrend::Mean;
  if (args.flag("detrend-linear")) p.detrend = Detrend::Linear;
  p.differentiateAngle = args.flag("differentiate");
  std::string why;
  if (!p.decimation.isValid(&why)) {
    err << "flexarm preprocess: " << why << "\n";
    return kExitUsage;
  }
  auto options = logReadOptions(args, err);
  if (!options) return kExitUsage;
  const std::string path = args.positional()[0];
  auto data = loadLog(path, *options, err);
  if (!data) return kExitBadInput;
  if (auto r = args.value("range")) {
    SampleRange range;
    if (!parseTimeRange(*r, *data, range, &why)) {
      err << "flexarm preprocess: " << why << "\n";
      return kExitUsage;
    }
    p.range = range;
  }
  if (p.differentiateAngle && !data->channel(columns::kMotorAngle)) {
    err << "flexarm: " << path << ": --differentiate needs a motor_angle_rad column\n";
    return kExitBadInput;
  }
  const auto t0 = std::chrono::steady_clock::now();
  IdData result = preprocess(*data, p);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!result.isValid(&why)) {
    err << "flexarm preprocess: the result is not usable: " << why << "\n";
    return kExitNumerical;
  }
  result.setMeta("preprocessed_from", path);
  storeRanges(result);
  ReadError werr;
  if (!writeFlexArmCsv(result, *outPath, &werr)) {
    err << "flexarm preprocess: " << werr.toString() << "\n";
    return kExitBadInput;
  }
  if (args.flag("json")) {
    nlohmann::json j = {{"input", path},
                        {"output", *outPath},
                        {"samples_in", data->samples()},
                        {"samples_out", result.samples()},
                        {"sample_rate_hz", result.sampleRateHz()},
                        {"decimate", p.decimation.factor},
                        {"filter", toString(p.decimation.filter)},
                        {"detrend", toString(p.detrend)},
                        {"differentiate", p.differentiateAngle},
                        {"seconds", seconds}};
    out << j.dump(2) << "\n";
  } else {
    out << "wrote " << *outPath << ": " << result.samples() << " samples at "
        << result.sampleRateHz() << " Hz\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
