// flexarm preprocess LOG [--resample RATE_HZ [--method M] [--max-gap S] [--with LOG2 ...]]
//                        [--decimate N] [--detrend] --out OUT.csv
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
    "log. Steps, in this order: resample, differentiate, cut to a range, decimate, detrend.\n\n"
    "  --out FILE            the FlexArm CSV log to write (required)\n"
    "  --resample RATE_HZ    put the log on a uniform grid at this rate first: irregular time\n"
    "                        stamps (jitter, dropped samples, duplicates, reversals; refused\n"
    "                        without this option) are reported and filled, and the rate is\n"
    "                        changed by any rational factor (polyphase FIR, >= 80 dB from the\n"
    "                        lower Nyquist frequency); empty fields mark channels not sampled\n"
    "                        at that time (channels at different rates)\n"
    "  --method linear|pchip|bandlimited\n"
    "                        how irregular time stamps are filled onto the grid (default\n"
    "                        bandlimited: exact for short gaps of a signal below 0.8 of the\n"
    "                        log's Nyquist frequency)\n"
    "  --max-gap S           longest gap to bridge, seconds (default: ten sample intervals);\n"
    "                        a longer one is refused with its place\n"
    "  --with LOG2           another log of the same experiment (same clock): its channels\n"
    "                        join on LOG's time base (repeatable; needs --resample)\n"
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

nlohmann::json timingJson(const ChannelGroup& g) {
  const TimingReport& t = g.timing;
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : t.events) {
    nlohmann::json j = {{"kind", toString(e.kind)}, {"time_s", e.time}, {"sample", e.index}};
    if (e.line > 0) j["line"] = e.line;
    if (e.kind == TimingEventKind::Gap) {
      j["gap_s"] = e.size;
      j["missing"] = e.missing;
    } else if (e.kind == TimingEventKind::Jitter) {
      j["deviation"] = e.size;
    } else if (e.kind == TimingEventKind::Reversal) {
      j["back_s"] = e.size;
    }
    events.push_back(j);
  }
  return {{"log", g.log + 1},
          {"channels", g.channels},
          {"irregular", g.irregular},
          {"rate_hz", g.sourceRateHz},
          {"up", g.factor.up},
          {"down", g.factor.down},
          {"offset_samples", g.offsetSamples},
          {"interval_s", t.interval},
          {"gaps", t.gaps},
          {"missing", t.missing},
          {"jitter", t.jitter},
          {"duplicates", t.duplicates},
          {"reversals", t.reversals},
          {"filled", g.fill.filled},
          {"retimed", g.fill.retimed},
          {"events", events},
          {"events_truncated", t.truncated},
          {"summary", t.summary()}};
}

nlohmann::json resampleJson(const UniformGridResult& r, const UniformGridOptions& o) {
  nlohmann::json groups = nlohmann::json::array();
  for (const auto& g : r.groups) groups.push_back(timingJson(g));
  return {{"rate_hz", o.rateHz},
          {"method", toString(o.method)},
          {"stopband", r.stopband},
          {"filled", r.filled},
          {"retimed", r.retimed},
          {"longest_gap_bridged_s", r.longestGapBridged},
          {"longest_gap_at_s", r.longestGapTime},
          {"message", r.message},
          {"groups", groups}};
}

}  // namespace

int runPreprocess(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = logReadOptionNames();
  for (const char* v : {"out", "decimate", "filter", "range", "resample", "method", "max-gap", "with"})
    valued.push_back(v);
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
  auto usage = [&](const std::string& why) {
    err << "flexarm preprocess: " << why << "\n";
    return kExitUsage;
  };
  PreprocessOptions p;
  if (!args.integer("decimate", p.decimation.factor, 1, 1000000)) return usage(args.error());
  if (auto f = args.value("filter")) {
    auto parsed = antiAliasFilterFromString(*f);
    if (!parsed) return usage("--filter must be fir, chebyshev or none, not '" + *f + "'");
    p.decimation.filter = *parsed;
  }
  if (args.flag("detrend") && args.flag("detrend-linear")) return usage("give --detrend or --detrend-linear, not both");
  if (args.flag("detrend")) p.detrend = Detrend::Mean;
  if (args.flag("detrend-linear")) p.detrend = Detrend::Linear;
  p.differentiateAngle = args.flag("differentiate");
  std::optional<UniformGridOptions> resample;
  if (args.value("resample")) {
    UniformGridOptions u;
    if (!args.number("resample", u.rateHz)) return usage(args.error());
    if (!(u.rateHz > 0.0)) return usage("--resample needs a rate above 0 Hz");
    if (auto m = args.value("method")) {
      auto parsed = interpolationMethodFromString(*m);
      if (!parsed) return usage("--method must be linear, pchip or bandlimited, not '" + *m + "'");
      u.method = *parsed;
    }
    if (args.value("max-gap")) {
      if (!args.number("max-gap", u.maxGapSeconds)) return usage(args.error());
      if (!(u.maxGapSeconds > 0.0)) return usage("--max-gap needs a duration above 0 s");
    }
    resample = u;
  } else {
    for (const char* needs : {"method", "max-gap", "with"})
      if (args.value(needs)) return usage(std::string("--") + needs + " belongs to --resample RATE_HZ");
  }
  std::string why;
  if (!p.isValid(&why)) return usage(why);
  auto options = logReadOptions(args, err);
  if (!options) return kExitUsage;
  // Resampling is the explicit step irregular time stamps wait for: only then are they read.
  options->keepIrregularTime = resample.has_value();
  const std::string path = args.positional()[0];
  auto data = loadLog(path, *options, err);
  if (!data) return kExitBadInput;
  const std::size_t samplesIn = data->samples();
  std::vector<IdData> others;
  for (const auto& w : args.values("with")) {
    auto other = loadLog(w, *options, err);
    if (!other) return kExitBadInput;
    others.push_back(std::move(*other));
  }
  if (p.differentiateAngle && !data->channel(columns::kMotorAngle)) {
    err << "flexarm: " << path << ": --differentiate needs a motor_angle_rad column\n";
    return kExitBadInput;
  }

  const auto t0 = std::chrono::steady_clock::now();
  // The resampling step first, so that --range is read against the new time base.
  std::optional<UniformGridResult> report;
  if (resample) {
    PreprocessOptions first;
    first.resample = resample;
    std::vector<const IdData*> extra;
    for (const auto& o : others) extra.push_back(&o);
    PreprocessResult r = runPreprocess(*data, first, {}, extra);
    if (r.termination != Termination::Converged) {
      err << "flexarm: " << path << ": " << r.message << "\n";
      return kExitBadInput;
    }
    data = std::move(r.data);
    report = std::move(r.resampling);
  }
  if (auto r = args.value("range")) {
    SampleRange range;
    if (!parseTimeRange(*r, *data, range, &why)) return usage(why);
    p.range = range;
  }
  PreprocessResult r = runPreprocess(*data, p);
  if (r.termination != Termination::Converged) {
    err << "flexarm: " << path << ": " << r.message << "\n";
    return kExitBadInput;
  }
  IdData result = std::move(r.data);
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
                        {"samples_in", samplesIn},
                        {"samples_out", result.samples()},
                        {"sample_rate_hz", result.sampleRateHz()},
                        {"decimate", p.decimation.factor},
                        {"filter", toString(p.decimation.filter)},
                        {"detrend", toString(p.detrend)},
                        {"differentiate", p.differentiateAngle},
                        {"seconds", seconds}};
    j["resample"] = report ? resampleJson(*report, *resample) : nlohmann::json(nullptr);
    out << j.dump(2) << "\n";
  } else {
    if (report) out << "resampled: " << report->message << "\n";
    out << "wrote " << *outPath << ": " << result.samples() << " samples at "
        << result.sampleRateHz() << " Hz\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
