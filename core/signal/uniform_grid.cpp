#include "core/signal/uniform_grid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

namespace flexarm {
namespace {

// Samples of one group on a uniform grid, ready for the rate change.
struct Source {
  std::vector<const std::vector<double>*> inputs;  // one per channel of the group
  std::vector<std::vector<double>> owned;          // storage when regularised
  double start = 0.0, interval = 0.0;
  std::size_t points = 0;
};

double declaredRate(const IdData& d) {
  const std::string s = d.meta("sample_rate_hz");
  if (s.empty()) return 0.0;
  try {
    const double v = std::stod(s);
    return v > 0.0 && std::isfinite(v) ? v : 0.0;
  } catch (const std::exception&) {
    return 0.0;
  }
}

// Rate of a uniform log: the declared rate when it agrees with the sample time, so that
// 0.000500000000000001 s stays 2000 Hz.
double uniformRate(const IdData& d) {
  const double declared = declaredRate(d);
  if (declared > 0.0 && std::abs(declared * d.sampleTime - 1.0) < 1e-9) return declared;
  return 1.0 / d.sampleTime;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

// The samples where every channel of the mask has a value, strictly increasing in time
// (duplicates averaged), and their timing.
struct Instants {
  std::vector<double> time;
  std::vector<std::vector<double>> values;  // per channel
};

Instants sortedInstants(const IdData& d, const std::vector<std::size_t>& rows,
                        const std::vector<std::size_t>& channels, double interval) {
  std::vector<std::size_t> order = rows;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return d.timeStamps[a] < d.timeStamps[b]; });
  Instants s;
  s.values.resize(channels.size());
  std::size_t count = 0;
  for (std::size_t r : order) {
    const double t = d.timeStamps[r];
    if (!s.time.empty() && t - s.time.back() <= 1e-6 * interval) {  // duplicate: running mean
      ++count;
      for (std::size_t c = 0; c < channels.size(); ++c)
        s.values[c].back() += (d.channels[channels[c]].values[r] - s.values[c].back()) / static_cast<double>(count);
      continue;
    }
    count = 1;
    s.time.push_back(t);
    for (std::size_t c = 0; c < channels.size(); ++c) s.values[c].push_back(d.channels[channels[c]].values[r]);
  }
  return s;
}

}  // namespace

bool UniformGridOptions::isValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(rateHz >= 0.0) || !std::isfinite(rateHz)) return fail("the new sample rate must be positive");
  if (!(maxGapSeconds >= 0.0)) return fail("the gap limit must be positive (or 0 for ten intervals)");
  if (!(jitterTolerance > 0.0 && jitterTolerance < 0.5))
    return fail("the jitter tolerance must lie between 0 and 0.5 of the interval");
  if (!(stopbandDb >= 20.0 && stopbandDb <= 200.0))
    return fail("the stopband attenuation must lie between 20 and 200 dB");
  if (threads < 0) return fail("the thread count must be 0 (one per core) or more");
  return true;
}

UniformGridResult resampleToUniform(const std::vector<const IdData*>& logs, const UniformGridOptions& o,
                                    const ProgressCallback& progress) {
  const auto clockStart = std::chrono::steady_clock::now();
  std::string why;
  if (!o.isValid(&why)) throw std::invalid_argument("resampleToUniform: " + why);
  if (logs.empty()) throw std::invalid_argument("resampleToUniform: no log");
  for (std::size_t l = 0; l < logs.size(); ++l)
    if (!logs[l] || !logs[l]->isValid(&why))
      throw std::invalid_argument("resampleToUniform: log " + std::to_string(l + 1) + ": " +
                                  (logs[l] ? why : std::string("missing")));
  UniformGridResult res;
  auto finish = [&](Termination t, std::string message) {
    res.termination = t;
    res.message = std::move(message);
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clockStart).count();
    return std::move(res);
  };
  auto cancelled = [&](double fraction, const char* stage) { return reportProgress(progress, fraction, stage); };

  // The budget, before any work: the new grid over the first log's span, for every channel of
  // every log, must fit the memory FlexArm gives one resampled log.
  if (o.rateHz > 0.0) {
    const IdData& first = *logs.front();
    const double span = first.isUniform() ? first.duration()
                                          : first.timeStamps.back() - first.timeStamps.front();
    std::size_t channels = 0;
    for (const IdData* l : logs) channels += l->channels.size();
    const double points = std::floor(span * o.rateHz) + 1.0;
    const double bytes = points * static_cast<double>(channels) * sizeof(double);
    if (!(bytes <= kMaxResampledBytes)) {
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "resampling to %.6g Hz would make %.4g samples a channel over the log's %.6g s, %.3g GB for "
                    "its %zu channels, more than the %.3g GB FlexArm gives a resampled log; the highest rate "
                    "that fits is %.4g Hz",
                    o.rateHz, points, span, bytes / 1e9, channels, kMaxResampledBytes / 1e9,
                    kMaxResampledBytes / (static_cast<double>(channels) * sizeof(double)) / std::max(span, 1e-300));
      return finish(Termination::Failed, buf);
    }
  }

  // 1. Groups of channels sharing their instants, each on its own uniform grid.
  std::vector<Source> sources;
  std::vector<std::vector<std::size_t>> groupChannels;  // channel indices in their log
  for (std::size_t l = 0; l < logs.size(); ++l) {
    const IdData& d = *logs[l];
    const std::string which = logs.size() > 1 ? "log " + std::to_string(l + 1) + ": " : "";
    if (d.channels.empty() || d.samples() < 2)
      return finish(Termination::Failed, which + "fewer than two samples to resample");
    if (d.isUniform()) {
      ChannelGroup g;
      g.log = l;
      g.sourceRateHz = uniformRate(d);
      g.timing.samples = g.timing.gridPoints = d.samples();
      g.timing.interval = d.sampleTime;
      g.timing.gridStart = d.startTime;
      Source s;
      std::vector<std::size_t> idx;
      for (std::size_t c = 0; c < d.channels.size(); ++c) {
        g.channels.push_back(d.channels[c].name);
        s.inputs.push_back(&d.channels[c].values);
        idx.push_back(c);
      }
      s.start = d.startTime;
      s.interval = d.sampleTime;
      s.points = d.samples();
      res.groups.push_back(std::move(g));
      sources.push_back(std::move(s));
      groupChannels.push_back(std::move(idx));
      continue;
    }
    // Channels with the same pattern of missing values (NaN) share their instants.
    std::vector<std::vector<char>> masks;
    std::vector<std::vector<std::size_t>> members;
    for (std::size_t c = 0; c < d.channels.size(); ++c) {
      std::vector<char> mask(d.samples());
      for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = !std::isnan(d.channels[c].values[i]);
      auto it = std::find(masks.begin(), masks.end(), mask);
      if (it == masks.end()) {
        masks.push_back(std::move(mask));
        members.push_back({c});
      } else {
        members[static_cast<std::size_t>(it - masks.begin())].push_back(c);
      }
    }
    for (std::size_t m = 0; m < masks.size(); ++m) {
      if (cancelled(0.1 * static_cast<double>(l) / static_cast<double>(logs.size()), "timing"))
        return finish(Termination::Cancelled, "resampling cancelled");
      ChannelGroup g;
      g.log = l;
      for (std::size_t c : members[m]) g.channels.push_back(d.channels[c].name);
      // Named in messages only when the log's channels have different instants.
      const std::string names = masks.size() > 1 ? joined(g.channels) + ": " : std::string();
      std::vector<std::size_t> rows;
      std::vector<double> t;
      std::vector<int> lines;
      for (std::size_t i = 0; i < masks[m].size(); ++i)
        if (masks[m][i]) {
          rows.push_back(i);
          t.push_back(d.timeStamps[i]);
          if (d.sourceLines.size() == d.samples()) lines.push_back(d.sourceLines[i]);
        }
      if (rows.size() < 2) return finish(Termination::Failed, which + names + "fewer than two samples");
      TimingOptions to;
      to.jitterTolerance = o.jitterTolerance;
      to.declaredRateHz = declaredRate(d);
      g.timing = analyzeTiming(t, lines, to);
      if (!(g.timing.interval > 0.0))
        return finish(Termination::Failed, which + names + "every sample has the same time stamp");
      const double limit = o.maxGapSeconds > 0.0 ? o.maxGapSeconds : 10.0 * g.timing.interval;
      if (g.timing.longestGap > limit) {
        std::string place = formatted("%.6g s", g.timing.longestGapTime);
        for (const auto& e : g.timing.events)
          if (e.kind == TimingEventKind::Gap && e.size == g.timing.longestGap && e.line > 0)
            place += ", line " + std::to_string(e.line);
        res.groups.push_back(g);  // the report shows where the gap is
        return finish(Termination::Failed,
                      which + names + "the gap of " + durationText(g.timing.longestGap) +
                          " before the sample at " + place + " is longer than the limit of " +
                          durationText(limit) + " for bridging gaps; raise the limit or cut the log there");
      }
      Instants inst = sortedInstants(d, rows, members[m], g.timing.interval);
      Source s;
      s.start = g.timing.gridStart;
      s.interval = g.timing.interval;
      s.points = g.timing.gridPoints;
      g.sourceRateHz = 1.0 / g.timing.interval;
      g.irregular = !g.timing.regular();
      if (g.irregular || inst.time.size() != s.points) {
        std::vector<const std::vector<double>*> in;
        for (const auto& v : inst.values) in.push_back(&v);
        s.owned = regularize(inst.time, in, s.start, s.interval, s.points, o.method, &g.fill);
        g.irregular = true;
        res.filled += g.fill.filled;
        res.retimed += g.fill.retimed;
        if (g.timing.longestGap > res.longestGapBridged) {
          res.longestGapBridged = g.timing.longestGap;
          res.longestGapTime = g.timing.longestGapTime;
        }
      } else {
        s.owned = std::move(inst.values);
      }
      for (const auto& v : s.owned) s.inputs.push_back(&v);
      res.groups.push_back(std::move(g));
      sources.push_back(std::move(s));
      groupChannels.push_back(members[m]);
    }
  }

  // 2. The new grid: the first group's grid start, at the new rate, over the common time.
  const double rate = o.rateHz > 0.0 ? o.rateHz : res.groups.front().sourceRateHz;
  double first = -HUGE_VAL, last = HUGE_VAL;
  for (const auto& s : sources) {
    first = std::max(first, s.start);
    last = std::min(last, s.start + static_cast<double>(s.points - 1) * s.interval);
  }
  if (last < first)
    return finish(Termination::Failed, "the logs do not overlap in time (the latest starts at " +
                                           formatted("%.6g s", first) + ", the earliest ends at " +
                                           formatted("%.6g s", last) + ")");
  const double anchor = sources.front().start;
  const double k0 = std::max(0.0, std::ceil((first - anchor) * rate - 1e-9));
  const double start = anchor + k0 / rate;
  const double count = std::floor((last - start) * rate + 1e-9) + 1.0;
  if (!(count >= 2.0))
    return finish(Termination::Failed, "fewer than two samples at " + formatted("%.6g Hz", rate) +
                                           " in the time all channels cover");
  const std::size_t K = static_cast<std::size_t>(count);

  // 3. Every group from its rate to the new one.
  const IdData& base = *logs.front();
  IdData out;
  out.metadata = base.metadata;
  out.startTime = start;
  const RationalFactor* baseFactor = nullptr;
  for (std::size_t gi = 0; gi < res.groups.size(); ++gi) {
    if (cancelled(0.2 + 0.8 * static_cast<double>(gi) / static_cast<double>(res.groups.size()), "resampling"))
      return finish(Termination::Cancelled, "resampling cancelled");
    ChannelGroup& g = res.groups[gi];
    const Source& s = sources[gi];
    const auto f = rationalFactor(g.sourceRateHz, rate);
    if (!f)
      return finish(Termination::Failed,
                    formatted("%.9g Hz", g.sourceRateHz) + " to " + formatted("%.9g Hz", rate) +
                        " is not a ratio of whole numbers up to 10000; choose a rate such as " +
                        formatted("%.6g Hz", g.sourceRateHz / std::max(1.0, std::round(g.sourceRateHz / rate))));
    g.factor = *f;
    double offset = (start - s.start) / s.interval;
    if (std::abs(offset - std::round(offset)) < 1e-6) offset = std::round(offset);
    g.offsetSamples = std::max(0.0, offset);
    ResampleOptions ro;
    ro.up = f->up;
    ro.down = f->down;
    ro.offset = g.offsetSamples;
    ro.outputs = K;
    ro.stopbandDb = o.stopbandDb;
    ro.threads = o.threads;
    auto values = resample(s.inputs, ro);
    const IdData& d = *logs[g.log];
    for (std::size_t c = 0; c < values.size(); ++c) {
      const Channel& src = d.channels[groupChannels[gi][c]];
      Channel ch{src.name, src.unit, src.role, std::move(values[c])};
      if (g.log > 0) {
        if (out.channel(ch.name)) ch.name = "log" + std::to_string(g.log + 1) + "_" + ch.name;
        if (ch.role != ChannelRole::None && out.withRole(ch.role)) ch.role = ChannelRole::None;
      }
      g.channels[c] = ch.name;
      out.channels.push_back(std::move(ch));
    }
    if (gi == 0) baseFactor = &g.factor;
  }
  // Keep the first log's channel order within its groups.
  std::stable_sort(out.channels.begin(), out.channels.end(), [&](const Channel& a, const Channel& b) {
    auto rank = [&](const Channel& c) {
      const int i = base.indexOf(c.name);
      return i < 0 ? static_cast<int>(base.channels.size()) : i;
    };
    return rank(a) < rank(b);
  });
  out.sampleTime = base.isUniform() ? base.sampleTime * baseFactor->down / baseFactor->up : 1.0 / rate;
  out.setMeta("sample_rate_hz", formatted("%.12g", rate));

  // Ranges of the first log, by time.
  auto carry = [&](const std::optional<SampleRange>& r) -> std::optional<SampleRange> {
    if (!r || r->empty() || r->end > base.samples()) return std::nullopt;
    const double b = std::ceil((base.timeAt(r->begin) - start) * rate - 1e-9);
    const double e = std::floor((base.timeAt(r->end - 1) - start) * rate + 1e-9) + 1.0;
    SampleRange s{static_cast<std::size_t>(std::clamp(b, 0.0, count)), static_cast<std::size_t>(std::clamp(e, 0.0, count))};
    if (s.empty()) return std::nullopt;
    return s;
  };
  out.estimationRange = carry(base.estimationRange);
  out.validationRange = carry(base.validationRange);
  res.data = std::move(out);

  // 4. What was done, in words.
  const ChannelGroup& g0 = res.groups.front();
  const double lowNyquist = 0.5 * std::min(rate, g0.sourceRateHz);
  res.stopband = formatted("%.0f dB", o.stopbandDb) + " from " + formatted("%.6g Hz", lowNyquist);
  std::string msg;
  if (g0.factor.up == g0.factor.down)
    msg = "kept at " + formatted("%.6g Hz", rate);
  else
    msg = formatted("%.6g Hz", g0.sourceRateHz) + " -> " + formatted("%.6g Hz", rate) + " (up " +
          std::to_string(g0.factor.up) + ", down " + std::to_string(g0.factor.down) +
          "; anti-alias FIR, " + res.stopband + ")";
  msg += ", " + std::to_string(K) + " samples";
  for (const auto& g : res.groups) {
    if (!g.irregular) continue;
    msg += "; time stamps";
    if (res.groups.size() > 1) msg += " of " + joined(g.channels);
    msg += ": " + g.timing.summary() + "; " + std::to_string(g.fill.filled) +
           (g.fill.filled == 1 ? " grid point" : " grid points") + " filled and " + std::to_string(g.fill.retimed) +
           (g.fill.retimed == 1 ? " sample" : " samples") + " retimed (" + toString(o.method) + ")";
    if (g.fill.pchipFallback) msg += ", " + std::to_string(g.fill.pchipFallback) + " points of long gaps by PCHIP";
  }
  if (res.filled) msg += "; longest gap bridged " + durationText(res.longestGapBridged) + " at " + formatted("%.6g s", res.longestGapTime);
  if (logs.size() > 1)
    msg += "; " + std::to_string(logs.size()) + " logs on the first log's time base from " + formatted("%.6g s", start);
  reportProgress(progress, 1.0, "resampled");
  return finish(Termination::Converged, msg);
}

UniformGridResult resampleToUniform(const IdData& log, const UniformGridOptions& options,
                                    const ProgressCallback& progress) {
  return resampleToUniform(std::vector<const IdData*>{&log}, options, progress);
}

}  // namespace flexarm
