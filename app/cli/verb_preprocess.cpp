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

OptionTable preprocessTable() {
  OptionTable t("flexarm preprocess LOG --out OUT.csv [options] [--json]",
                "Prepares a log for identification as in the seed's Section 5.2 and writes a FlexArm CSV log. "
                "Steps, in this order: resample, differentiate, cut to a range, decimate, detrend.");
  auto above0 = [](Option o) {
    o.minOpen = true;
    return o;
  };
  t.add(required(textOption("out", "FILE", "the FlexArm CSV log to write")))
      .add(above0(numberOption("resample", "RATE_HZ", 0.0, 1e308, "",
                               "put the log on a uniform grid at this rate first: irregular time stamps (jitter, "
                               "dropped samples, duplicates, reversals; refused without this option) are reported "
                               "and filled, and the rate is changed by any rational factor (polyphase FIR, >= 80 dB "
                               "from the lower Nyquist frequency); empty fields mark channels not sampled at that "
                               "time (channels at different rates)")))
      .add(choiceOption("method", {"linear", "pchip", "bandlimited"}, "bandlimited",
                        "how irregular time stamps are filled onto the grid (bandlimited: exact for short gaps of a "
                        "signal below 0.8 of the log's Nyquist frequency)"))
      .add(above0(numberOption("max-gap", "S", 0.0, 1e308, "", "longest gap to bridge, seconds (default: ten sample "
                                                              "intervals); a longer one is refused with its place")))
      .add(textOption("with", "LOG2", "another log of the same experiment (same clock): its channels join on LOG's "
                                      "time base (needs --resample)",
                      true))
      .add(flagOption("differentiate", "add motor_velocity_rad_s = d/dt motor_angle_rad as the output"))
      .add(textOption("range", "A:B", "keep only the samples from A to B seconds"))
      .add(integerOption("decimate", "N", 1, 1000000, "1", "keep every N-th sample after the anti-alias filter"))
      .add(choiceOption("filter", {"fir", "chebyshev", "none"}, "fir",
                        "anti-alias filter: linear-phase FIR with >= 80 dB stopband from the new Nyquist frequency, "
                        "order-8 Chebyshev I run forward and backward, or none (aliasing)"))
      .add(flagOption("detrend", "remove the means of input and output"))
      .add(flagOption("detrend-linear", "remove linear trends of input and output"))
      .add(flagOption("json", "print a JSON summary of the result"))
      .group("Reading the log")
      .add(logReadOptionList());
  return t;
}

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
  ArgParser args(preprocessTable());
  if (auto rc = parseArguments(args, argv, "preprocess", out, err)) return *rc;
  if (args.positional().size() != 1) {
    err << "flexarm preprocess: expected exactly one LOG\n" << args.table().help();
    return kExitUsage;
  }
  const std::string outPath = args.text("out");
  auto usage = [&](const std::string& why) {
    err << "flexarm preprocess: " << why << "\n";
    return kExitUsage;
  };
  PreprocessOptions p;
  p.decimation.factor = static_cast<int>(args.integer("decimate"));
  p.decimation.filter = *antiAliasFilterFromString(args.text("filter"));
  if (args.flag("detrend") && args.flag("detrend-linear")) return usage("give --detrend or --detrend-linear, not both");
  if (args.flag("detrend")) p.detrend = Detrend::Mean;
  if (args.flag("detrend-linear")) p.detrend = Detrend::Linear;
  p.differentiateAngle = args.flag("differentiate");
  std::optional<UniformGridOptions> resample;
  if (args.value("resample")) {
    UniformGridOptions u;
    u.rateHz = args.number("resample");
    u.method = *interpolationMethodFromString(args.text("method"));
    if (args.value("max-gap")) u.maxGapSeconds = args.number("max-gap");
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
  if (!writeFlexArmCsv(result, outPath, &werr)) {
    err << "flexarm preprocess: " << werr.toString() << "\n";
    return kExitBadInput;
  }
  if (args.flag("json")) {
    nlohmann::json j = {{"input", path},
                        {"output", outPath},
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
    out << "wrote " << outPath << ": " << result.samples() << " samples at "
        << result.sampleRateHz() << " Hz\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
