#include "core/ident/fit_data.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/common/text.h"
#include "core/signal/excitation.h"

namespace flexarm {

bool FitDataOptions::isValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (decimation < 1) return fail("the decimation factor must be at least 1");
  if (decimation > 1) {
    DecimateOptions d;
    d.factor = decimation;
    d.stopbandDb = stopbandDb;
    if (!d.isValid(why)) return false;
  }
  for (const auto* r : {&estimation, &validation})
    if (*r && !((*r)->start < (*r)->end && std::isfinite((*r)->start) && std::isfinite((*r)->end)))
      return fail(std::string("the ") + (r == &estimation ? "estimation" : "validation") +
                  " range must be finite with start < end");
  if (minimumSamples < 1) return fail("the minimum number of samples must be at least 1");
  return true;
}

std::string PreparedData::note() const {
  std::string text;
  for (const auto& s : steps) text += (text.empty() ? "" : ", ") + s;
  return text;
}

namespace {

Eigen::VectorXd segment(const Eigen::VectorXd& x, const SampleRange& r) {
  if (x.size() == 0) return {};
  return x.segment(static_cast<Eigen::Index>(r.begin), static_cast<Eigen::Index>(r.size()));
}

Eigen::VectorXd vectorOf(const Channel* c) {
  if (!c) return {};
  return Eigen::Map<const Eigen::VectorXd>(c->values.data(), static_cast<Eigen::Index>(c->values.size()));
}

std::string seconds(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", t);
  return buf;
}

}  // namespace

Eigen::VectorXd PreparedData::estimationInput() const { return segment(u, estimation); }
Eigen::VectorXd PreparedData::estimationOutput() const { return segment(y, estimation); }
Eigen::VectorXd PreparedData::estimationReference() const { return segment(r, estimation); }

PreparedData prepareFitData(const IdData& data, const FitDataOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("prepareFitData: " + why);
  PreparedData out;
  auto fail = [&out](std::string text) {
    out.termination = Termination::Failed;
    out.message = std::move(text);
    return out;
  };
  // 1. Channels: a small data set holding only what the fit uses (and the angle).
  auto pick = [&data](const std::string& name, ChannelRole role) {
    return name.empty() ? data.withRole(role) : data.channel(name);
  };
  const Channel* in = pick(options.input, ChannelRole::Input);
  const Channel* outCh = pick(options.output, ChannelRole::Output);
  const Channel* ref = pick(options.reference, ChannelRole::Reference);
  if (!in || !outCh) {
    const bool named = !(in ? options.output : options.input).empty();
    const std::string what = in ? "output" : "input";
    return fail(named ? "the log has no channel '" + (in ? options.output : options.input) +
                            "' for the " + what
                      : "the log has no " + what + " channel");
  }
  if (!options.reference.empty() && !ref)
    return fail("the log has no channel '" + options.reference + "' for the reference");
  if (in == outCh) return fail("the input and the output are the same channel " + inQuotes(in->name));
  // Dead data (a stuck encoder, a zero torque, values too large to square) are refused here,
  // before any estimator or diagnosis runs on them.
  if (std::string dead = deadDataProblem(data, {in->name, outCh->name, columns::kArmAngle}); !dead.empty()) return fail(dead);
  IdData d;
  d.sampleTime = data.sampleTime;
  d.startTime = data.startTime;
  d.setChannel(Channel{in->name, in->unit, ChannelRole::Input, in->values});
  d.setChannel(Channel{outCh->name, outCh->unit, ChannelRole::Output, outCh->values});
  if (ref && ref != in && ref != outCh)
    d.setChannel(Channel{ref->name, ref->unit, ChannelRole::Reference, ref->values});
  const Channel* angle = data.channel(columns::kMotorAngle);
  const bool outputIsAngle = outCh->name == columns::kMotorAngle;
  if (angle && !outputIsAngle && angle != in && angle != ref)
    d.setChannel(Channel{angle->name, angle->unit, ChannelRole::None, angle->values});
  const Channel* arm = data.channel(columns::kArmAngle);
  if (arm && arm != in && arm != outCh && arm != ref)
    d.setChannel(Channel{arm->name, arm->unit, ChannelRole::None, arm->values});
  if (!d.isValid(&why)) return fail("the log's channels are not usable: " + why);
  if (d.samples() < 2) return fail("the log holds fewer than two samples");
  out.inputName = in->name;
  out.outputName = outCh->name;
  out.referenceName = ref ? ref->name : "";
  out.closedLoop = ref != nullptr;

  // 2. The motor velocity from the angle: the angle stays as a channel of its own.
  if (options.velocityOutput && outputIsAngle) {
    d = addDerivative(d, columns::kMotorAngle, columns::kMotorVelocity, true);
    d.channel(columns::kMotorAngle)->role = ChannelRole::None;
    out.outputName = columns::kMotorVelocity;
    out.differentiated = true;
    out.steps.push_back("motor velocity from the angle (central differences)");
  }
  // 3. Decimation.
  if (options.decimation > 1) {
    DecimateOptions dec;
    dec.factor = options.decimation;
    dec.stopbandDb = options.stopbandDb;
    if (d.samples() < static_cast<std::size_t>(4 * options.decimation))
      return fail("the log holds too few samples (" + std::to_string(d.samples()) +
                  ") to decimate by " + std::to_string(options.decimation));
    const std::vector<double> fine = d.input()->values;
    d = decimate(d, dec);
    out.decimation = options.decimation;
    out.steps.push_back("decimated by " + std::to_string(options.decimation) + " (anti-alias FIR)");
    if (options.decimatedInput == FitDataOptions::DecimatedInput::HeldMean) {
      std::vector<double>& held = d.channel(in->name)->values;
      const std::size_t r = static_cast<std::size_t>(options.decimation);
      for (std::size_t k = 0; k < held.size(); ++k) {
        const std::size_t b = k * r, e = std::min(fine.size(), b + r);
        double sum = 0.0;
        for (std::size_t j = b; j < e; ++j) sum += fine[j];
        held[k] = sum / static_cast<double>(e - b);
      }
      out.steps.push_back("input as its mean over each held period");
    }
  }
  out.sampleTime = d.sampleTime;
  out.startTime = d.startTime;
  out.u = vectorOf(d.input());
  out.y = vectorOf(d.output());
  out.r = vectorOf(d.withRole(ChannelRole::Reference));
  out.angle = vectorOf(d.channel(columns::kMotorAngle));
  if (arm && arm != in && arm != outCh && arm != ref) out.arm = vectorOf(d.channel(columns::kArmAngle));

  // 4. Ranges in seconds become sample ranges of the data as they now are.
  const std::string span = seconds(d.timeAt(0)) + "-" + seconds(d.timeAt(d.samples() - 1)) + " s";
  auto resolve = [&](const std::optional<SecondsRange>& asked, const char* what, SampleRange& target) {
    if (!asked) return true;
    target = samplesIn(d, *asked);
    if (!target.empty()) return true;
    why = std::string("the ") + what + " range " + seconds(asked->start) + "-" + seconds(asked->end) +
          " s holds no samples of the log (" + span + ")";
    return false;
  };
  if (!resolve(options.estimation, "estimation", out.estimation) ||
      !resolve(options.validation, "validation", out.validation))
    return fail(why);
  if (out.estimation.empty()) out.estimation = {0, d.samples()};
  if (out.estimation.size() < static_cast<std::size_t>(options.minimumSamples))
    return fail("the estimation range holds only " + std::to_string(out.estimation.size()) +
                " samples (" + std::to_string(options.minimumSamples) + " needed)");

  // 5. Means of the estimation range.
  if (options.removeMeans) {
    out.inputMean = out.estimationInput().mean();
    out.outputMean = out.estimationOutput().mean();
    out.u.array() -= out.inputMean;
    out.y.array() -= out.outputMean;
    if (out.r.size()) {
      out.referenceMean = out.estimationReference().mean();
      out.r.array() -= out.referenceMean;
    }
    out.steps.push_back("estimation means removed");
  }
  out.termination = Termination::Converged;
  out.message = "prepared " + std::to_string(out.estimation.size()) + " estimation samples";
  return out;
}

}  // namespace flexarm
