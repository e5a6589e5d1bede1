#include "core/signal/preprocess.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "core/common/text.h"
#include "core/common/fft.h"

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Decimation is the up = 1 case of the rational resampler.
ResampleOptions resampleOptions(const DecimateOptions& d) {
  ResampleOptions r;
  r.down = d.factor;
  r.filter = d.filter;
  r.stopbandDb = d.stopbandDb;
  return r;
}

}  // namespace

std::vector<double> differentiate(const std::vector<double>& x, double sampleTime) {
  if (!(sampleTime > 0.0)) throw std::invalid_argument("differentiate: sample time must be > 0");
  const std::size_t n = x.size();
  std::vector<double> d(n, 0.0);
  if (n < 2) return d;
  if (n == 2) {
    d[0] = d[1] = (x[1] - x[0]) / sampleTime;
    return d;
  }
  const double h2 = 2.0 * sampleTime;
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - x[i - 1]) / h2;
  d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / h2;
  d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / h2;
  return d;
}

IdData addDerivative(const IdData& data, const std::string& from, const std::string& to,
                     bool makeOutput) {
  const Channel* src = data.channel(from);
  if (!src) throw std::invalid_argument("addDerivative: the data have no channel " + inQuotes(from));
  IdData out = data;
  Channel c;
  c.name = to;
  c.unit = unitFromColumnName(to);
  if (c.unit.empty()) c.unit = src->unit.empty() ? "1/s" : src->unit + "/s";
  c.values = differentiate(src->values, data.sampleTime);
  out.setChannel(std::move(c));
  if (makeOutput) out.setRole(to, ChannelRole::Output);
  return out;
}

bool DecimateOptions::isValid(std::string* why) const {
  if (factor < 1) {
    if (why) *why = "the decimation factor must be 1 or more";
    return false;
  }
  if (factor > 10000) {
    if (why) *why = "the decimation factor must be at most 10000";
    return false;
  }
  if (!(stopbandDb >= 20.0 && stopbandDb <= 200.0)) {
    if (why) *why = "the stopband attenuation must lie between 20 and 200 dB";
    return false;
  }
  return true;
}

std::vector<double> decimate(const std::vector<double>& x, const DecimateOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("decimate: " + why);
  return resample(x, resampleOptions(options));
}

IdData decimate(const IdData& data, const DecimateOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("decimate: " + why);
  if (!data.isUniform())
    throw std::invalid_argument("decimate: the data have irregular time stamps; resample them first");
  if (options.factor == 1) return data;
  IdData out;
  out.sampleTime = data.sampleTime * options.factor;
  out.startTime = data.startTime;
  out.metadata = data.metadata;
  std::vector<const std::vector<double>*> inputs;
  for (const auto& c : data.channels) inputs.push_back(&c.values);
  auto outputs = resample(inputs, resampleOptions(options));
  for (std::size_t i = 0; i < data.channels.size(); ++i) {
    const Channel& c = data.channels[i];
    out.channels.push_back({c.name, c.unit, c.role, std::move(outputs[i])});
  }
  const std::size_t r = static_cast<std::size_t>(options.factor);
  auto scale = [&](const std::optional<SampleRange>& in) -> std::optional<SampleRange> {
    if (!in) return std::nullopt;
    SampleRange s{(in->begin + r - 1) / r, (in->end + r - 1) / r};
    s.end = std::min(s.end, out.samples());
    if (s.empty()) return std::nullopt;
    return s;
  };
  out.estimationRange = scale(data.estimationRange);
  out.validationRange = scale(data.validationRange);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", out.sampleRateHz());
  out.setMeta("sample_rate_hz", buf);
  return out;
}

const char* toString(Detrend d) {
  switch (d) {
    case Detrend::None: return "none";
    case Detrend::Mean: return "mean";
    case Detrend::Linear: return "linear";
  }
  return "none";
}

std::optional<Detrend> detrendFromString(std::string_view s) {
  for (Detrend d : {Detrend::None, Detrend::Mean, Detrend::Linear})
    if (s == toString(d)) return d;
  return std::nullopt;
}

std::vector<double> detrend(const std::vector<double>& x, Detrend kind) {
  std::vector<double> y = x;
  const std::size_t n = x.size();
  if (n == 0 || kind == Detrend::None) return y;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  if (kind == Detrend::Mean || n < 2) {
    for (double& v : y) v -= mean;
    return y;
  }
  // Least-squares line through (i, x_i) with i centred for accuracy.
  const double ic = 0.5 * static_cast<double>(n - 1);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double di = static_cast<double>(i) - ic;
    sxy += di * (x[i] - mean);
    sxx += di * di;
  }
  const double slope = sxy / sxx;
  for (std::size_t i = 0; i < n; ++i) y[i] -= mean + slope * (static_cast<double>(i) - ic);
  return y;
}

IdData detrend(const IdData& data, Detrend kind, bool allChannels) {
  IdData out = data;
  for (auto& c : out.channels)
    if (allChannels || c.role == ChannelRole::Input || c.role == ChannelRole::Output)
      c.values = detrend(c.values, kind);
  if (kind != Detrend::None) out.setMeta("detrend", toString(kind));
  return out;
}

AmplitudeSpectrum amplitudeSpectrum(const std::vector<double>& x, double sampleTime,
                                    int segmentLength) {
  AmplitudeSpectrum s;
  const int n = static_cast<int>(x.size());
  if (n < 8 || !(sampleTime > 0.0)) return s;
  int len = segmentLength;
  if (len <= 0) {
    len = 8;
    while (len * 2 <= std::min(n, 8192)) len *= 2;
  }
  len = std::min(len, n);
  std::vector<double> window(static_cast<std::size_t>(len));
  double wsum = 0.0;
  for (int i = 0; i < len; ++i) {
    window[static_cast<std::size_t>(i)] = 0.5 - 0.5 * std::cos(2.0 * kPi * i / len);
    wsum += window[static_cast<std::size_t>(i)];
  }
  const int bins = len / 2 + 1;
  std::vector<double> power(static_cast<std::size_t>(bins), 0.0);
  std::vector<double> in(static_cast<std::size_t>(len));
  std::vector<std::complex<double>> out(static_cast<std::size_t>(bins));
  const int step = std::max(1, len / 2);
  int segments = 0;
  for (int start = 0; start + len <= n; start += step) {
    double mean = 0.0;
    for (int i = 0; i < len; ++i) mean += x[static_cast<std::size_t>(start + i)];
    mean /= len;
    for (int i = 0; i < len; ++i)
      in[static_cast<std::size_t>(i)] =
          (x[static_cast<std::size_t>(start + i)] - mean) * window[static_cast<std::size_t>(i)];
    realDft(in.data(), len, out.data());
    for (int k = 0; k < bins; ++k) {
      const auto& X = out[static_cast<std::size_t>(k)];
      power[static_cast<std::size_t>(k)] += X.real() * X.real() + X.imag() * X.imag();
    }
    ++segments;
  }
  s.frequencyHz.resize(static_cast<std::size_t>(bins));
  s.amplitude.resize(static_cast<std::size_t>(bins));
  for (int k = 0; k < bins; ++k) {
    s.frequencyHz[static_cast<std::size_t>(k)] = k / (len * sampleTime);
    const double mag = std::sqrt(power[static_cast<std::size_t>(k)] / segments);
    s.amplitude[static_cast<std::size_t>(k)] = (k == 0 ? 1.0 : 2.0) * mag / wsum;
  }
  return s;
}

bool PreprocessOptions::isValid(std::string* why) const {
  if (resample && !resample->isValid(why)) return false;
  if (!decimation.isValid(why)) return false;
  if (range && range->empty()) {
    if (why) *why = "the selected range is empty";
    return false;
  }
  return true;
}

PreprocessResult runPreprocess(const IdData& data, const PreprocessOptions& options,
                               const ProgressCallback& progress,
                               const std::vector<const IdData*>& otherLogs) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("preprocess: " + why);
  if (!otherLogs.empty() && !options.resample)
    throw std::invalid_argument("preprocess: further logs join only through the resampling step");
  PreprocessResult r;
  auto finish = [&](Termination t, std::string message) {
    r.termination = t;
    r.message = std::move(message);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::move(r);
  };
  IdData d;
  if (options.resample) {
    std::vector<const IdData*> logs{&data};
    logs.insert(logs.end(), otherLogs.begin(), otherLogs.end());
    UniformGridResult u = resampleToUniform(logs, *options.resample, progress);
    if (u.termination != Termination::Converged) {
      std::string message = u.message;
      r.resampling = std::move(u);  // its time-stamp report shows where the problem is
      return finish(r.resampling->termination, message);
    }
    d = std::move(u.data);
    u.data = IdData{};
    r.resampling = std::move(u);
  } else if (!data.isUniform()) {
    TimingOptions to;
    const TimingReport timing = analyzeTiming(data.timeStamps, data.sourceLines, to);
    return finish(Termination::Failed, "the time stamps are irregular (" + timing.summary() +
                                           "): resample the log onto a uniform grid first");
  } else {
    d = data;
  }
  if (options.differentiateAngle) {
    if (!d.channel(columns::kMotorAngle))
      return finish(Termination::Failed, "differentiation needs a motor_angle_rad channel");
    d = addDerivative(d);
  }
  if (options.range) {
    if (options.range->end > d.samples())
      return finish(Termination::Failed, "the range ends at sample " + std::to_string(options.range->end) +
                                             " but the data have " + std::to_string(d.samples()));
    d = d.select(*options.range);
  }
  d = decimate(d, options.decimation);
  if (options.detrend != Detrend::None) d = detrend(d, options.detrend);
  r.data = std::move(d);
  return finish(Termination::Converged, r.resampling ? r.resampling->message : std::string());
}

IdData preprocess(const IdData& data, const PreprocessOptions& options) {
  PreprocessResult r = runPreprocess(data, options);
  if (r.termination != Termination::Converged) throw std::invalid_argument(r.message);
  return std::move(r.data);
}

}  // namespace flexarm
