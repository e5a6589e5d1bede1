#include "core/io/log_mapping.h"

#include <cmath>
#include <cstdio>

#include "core/common/text.h"
#include "core/io/reader_support.h"

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct UnitInfo {
  SignalUnit unit;
  const char* text;
  double factor;
  bool linear, velocity;
};

const UnitInfo kUnits[] = {
    {SignalUnit::Rad, "rad", 1.0, false, false},
    {SignalUnit::Deg, "deg", kPi / 180.0, false, false},
    {SignalUnit::Rev, "rev", 2.0 * kPi, false, false},
    {SignalUnit::RadPerS, "rad/s", 1.0, false, true},
    {SignalUnit::DegPerS, "deg/s", kPi / 180.0, false, true},
    {SignalUnit::Rpm, "rpm", 2.0 * kPi / 60.0, false, true},
    {SignalUnit::M, "m", 1.0, true, false},
    {SignalUnit::Mm, "mm", 1e-3, true, false},
    {SignalUnit::MPerS, "m/s", 1.0, true, true},
    {SignalUnit::MmPerS, "mm/s", 1e-3, true, true},
};

const UnitInfo& info(SignalUnit u) {
  for (const auto& i : kUnits)
    if (i.unit == u) return i;
  return kUnits[0];
}

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

std::string join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// The FlexArm name of the converted output.
const char* outputColumn(SignalUnit u) {
  if (isLinear(u)) return isVelocity(u) ? columns::kMotorLinearVelocity : columns::kMotorPosition;
  return isVelocity(u) ? columns::kMotorVelocity : columns::kMotorAngle;
}

bool isFlexArmOutput(const std::string& name) {
  return name == columns::kMotorAngle || name == columns::kMotorVelocity ||
         name == columns::kMotorPosition || name == columns::kMotorLinearVelocity;
}

}  // namespace

const char* toString(SignalUnit u) { return info(u).text; }

std::optional<SignalUnit> signalUnitFromString(std::string_view s) {
  for (const auto& i : kUnits)
    if (s == i.text) return i.unit;
  if (s == "degree" || s == "degrees") return SignalUnit::Deg;
  if (s == "rad_s") return SignalUnit::RadPerS;
  if (s == "deg_s") return SignalUnit::DegPerS;
  return std::nullopt;
}

double toSiFactor(SignalUnit u) { return info(u).factor; }
bool isLinear(SignalUnit u) { return info(u).linear; }
bool isVelocity(SignalUnit u) { return info(u).velocity; }

const char* toString(EncoderSide s) { return s == EncoderSide::Motor ? "motor" : "arm"; }

std::optional<EncoderSide> encoderSideFromString(std::string_view s) {
  if (s == "motor") return EncoderSide::Motor;
  if (s == "arm" || s == "link" || s == "load") return EncoderSide::Arm;
  return std::nullopt;
}

std::optional<double> parseGearRatio(std::string_view text, std::string* why) {
  const std::string t = io::trim(text);
  const std::size_t slash = t.find('/');
  double value = 0.0;
  bool ok = false;
  if (slash == std::string::npos) {
    ok = io::parseNumber(t, value) == io::FieldStatus::Ok;
  } else {
    double a = 0.0, b = 0.0;
    ok = io::parseNumber(std::string_view(t).substr(0, slash), a) == io::FieldStatus::Ok &&
         io::parseNumber(std::string_view(t).substr(slash + 1), b) == io::FieldStatus::Ok && b != 0.0;
    value = ok ? a / b : 0.0;
  }
  if (!ok || !std::isfinite(value) || !(value > 0.0)) {
    if (why)
      *why = "the gear ratio '" + t + "' must be a positive number arm/motor, e.g. 1/256.86 or 0.00389";
    return std::nullopt;
  }
  return value;
}

std::string invertedGearRatio(std::string_view text) {
  if (!parseGearRatio(text, nullptr)) return {};
  const std::string t = io::trim(text);
  const std::size_t slash = t.find('/');
  if (slash == std::string::npos) return "1/" + t;
  const std::string a = io::trim(std::string_view(t).substr(0, slash));
  const std::string b = io::trim(std::string_view(t).substr(slash + 1));
  double one = 0.0;
  if (io::parseNumber(a, one) == io::FieldStatus::Ok && one == 1.0) return b;
  return b + "/" + a;
}

bool LogMapping::isValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!gearRatio.empty()) {
    const std::optional<double> r = parseGearRatio(gearRatio, why);
    if (!r) return false;
    if (*r > 1.0)
      return fail("the gear ratio " + inQuotes(io::trim(gearRatio)) +
                  " is above 1: it is arm turns per motor turn (arm/motor), and a reduction of " +
                  io::trim(gearRatio) + " motor turns per arm turn is " + invertedGearRatio(gearRatio));
  }
  if (!std::isfinite(inputScale) || inputScale == 0.0)
    return fail("the input scale must be a finite number other than 0");
  if (armUnit && (isLinear(*armUnit) || isVelocity(*armUnit)))
    return fail("the arm encoder's unit must be an angle: rad, deg or rev");
  if (outputSide == EncoderSide::Arm && outputUnit && isLinear(*outputUnit))
    return fail("a linear output is the load's position: it has no arm side to convert from");
  if (outputSide == EncoderSide::Arm && gearRatio.empty())
    return fail("an output given on the arm side needs the gear ratio (arm/motor, e.g. 1/256.86) "
                "to be turned into the motor angle");
  return true;
}

bool LogMapping::operator==(const LogMapping& o) const {
  return time == o.time && input == o.input && output == o.output && arm == o.arm && reference == o.reference &&
         outputUnit == o.outputUnit && armUnit == o.armUnit && outputSide == o.outputSide &&
         gearRatio == o.gearRatio && inputScale == o.inputScale;
}

std::vector<std::string> describeMapping(const LogMapping& m) {
  std::vector<std::string> out;
  const bool prismatic = m.outputUnit && isLinear(*m.outputUnit);
  const std::optional<double> r = m.gearRatio.empty() ? std::nullopt : parseGearRatio(m.gearRatio, nullptr);
  if (!m.time.empty()) out.push_back("time = " + m.time);
  if (!m.input.empty() || m.inputScale != 1.0 || m.convertsOutput()) {
    std::string s = "input ";
    s += m.convertsOutput() || m.inputScale != 1.0 ? (prismatic ? columns::kForceRef : columns::kTorqueRef)
                                                   : "";
    s += (s.back() == ' ' ? "" : " = ");
    if (m.inputScale != 1.0) s += number(m.inputScale) + " x ";
    s += m.input.empty() ? std::string("the file's input") : m.input;
    out.push_back(s);
  }
  if (!m.output.empty() || m.convertsOutput()) {
    std::string s = "output ";
    if (m.convertsOutput()) {
      const SignalUnit u = m.outputUnit.value_or(SignalUnit::Rad);
      s += std::string(outputColumn(u)) + " = " + (m.output.empty() ? std::string("the file's output") : m.output) +
           " in " + toString(u);
      if (m.outputSide == EncoderSide::Arm && r)
        s += " on the arm side, times " + number(1.0 / *r) + " (gear ratio " + m.gearRatio + ")";
      else if (m.outputSide)
        s += " on the motor side";
    } else {
      s += "= " + m.output;
    }
    out.push_back(s);
  }
  if (!m.reference.empty()) {
    std::string s = "reference ";
    const SignalUnit u = m.outputUnit.value_or(SignalUnit::Rad);
    if (m.convertsOutput() && !isVelocity(u))
      s += std::string(isLinear(u) ? columns::kPositionRef : columns::kAngleRef) + " = " + m.reference + " as the output";
    else
      s += "= " + m.reference;
    out.push_back(s);
  }
  if (!m.arm.empty())
    out.push_back(std::string("arm ") + columns::kArmAngle + " = " + m.arm + " in " +
                  toString(m.armUnit.value_or(SignalUnit::Rad)));
  if (r && m.outputSide != EncoderSide::Arm) out.push_back("gear ratio " + m.gearRatio);
  return out;
}

bool applyMapping(IdData& data, const MappedChannels& found, const LogMapping& m, bool foreign,
                  std::vector<std::string>& warnings, std::string* why) {
  if (!m.isValid(why)) return false;
  const auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  const double ratio = m.gearRatio.empty() ? 0.0 : parseGearRatio(m.gearRatio, nullptr).value_or(0.0);
  const bool prismatic = m.outputUnit && isLinear(*m.outputUnit);
  const auto channel = [&](int i) -> Channel* {
    return i >= 0 && static_cast<std::size_t>(i) < data.channels.size() ? &data.channels[static_cast<std::size_t>(i)]
                                                                          : nullptr;
  };
  // A channel takes a FlexArm name only when no other channel has it already.
  const auto rename = [&](Channel& c, const char* name, const char* unit, const std::string& source) {
    for (const Channel& other : data.channels)
      if (&other != &c && other.name == name)
        return fail(std::string("the log already has a channel ") + name + ", so " + source +
                    " cannot become it; map that channel instead, or leave its unit unsaid");
    c.name = name;
    c.unit = unit;
    return true;
  };
  const auto scale = [](Channel& c, double k) {
    if (k != 1.0)
      for (double& v : c.values) v *= k;
  };
  // One channel cannot play two parts (a header name or column given twice).
  const std::pair<int, const std::string*> parts[] = {{found.input, &found.inputSource},
                                                      {found.output, &found.outputSource},
                                                      {found.arm, &found.armSource},
                                                      {found.reference, &found.referenceSource}};
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b)
      if (parts[a].first >= 0 && parts[a].first == parts[b].first)
        return fail(*parts[a].second + " is named for two parts (input, output, arm angle, reference): each "
                                       "needs a signal of its own");
  Channel* in = channel(found.input);
  Channel* out = channel(found.output);
  Channel* arm = channel(found.arm);
  Channel* ref = channel(found.reference);
  double outputFactor = 1.0;  // what the output was multiplied by (the reference shares it)
  if (in) {
    // Nothing said of the input of a foreign file (no scale, no units at all): read as stored,
    // which a physical model takes as the motor torque in N m.
    if (foreign && !m.convertsOutput() && m.inputScale == 1.0 && in->name != columns::kTorqueRef)
      warnings.push_back("the input " + found.inputSource +
                         " is read as stored: a physical model takes it as the motor torque in N m (say its scale "
                         "and the output's unit: --input-scale K, --output-unit)");
    scale(*in, m.inputScale);
    if ((m.convertsOutput() || m.inputScale != 1.0) &&
        !rename(*in, prismatic ? columns::kForceRef : columns::kTorqueRef, prismatic ? "N" : "N m",
                found.inputSource))
      return false;
  }
  if (out) {
    if (m.convertsOutput()) {
      const SignalUnit u = m.outputUnit.value_or(SignalUnit::Rad);
      if (!m.outputUnit)
        warnings.push_back("the output " + found.outputSource +
                           " is taken in rad: its unit was not given (--output-unit)");
      double k = toSiFactor(u);
      if (m.outputSide == EncoderSide::Arm) k /= ratio;  // isValid: a gear ratio is given
      if (!m.outputSide && !prismatic)
        warnings.push_back("the output " + found.outputSource +
                           " is taken as the motor shaft's: its side was not given (--output-side motor|arm)");
      scale(*out, k);
      outputFactor = k;
      const char* name = outputColumn(u);
      if (!rename(*out, name, isLinear(u) ? (isVelocity(u) ? "m/s" : "m") : (isVelocity(u) ? "rad/s" : "rad"),
                  found.outputSource))
        return false;
    } else if (foreign && !isFlexArmOutput(out->name)) {
      warnings.push_back("the output " + found.outputSource +
                         " is read as stored, in no stated unit: a physical model takes it as the motor "
                         "angle in rad (say its unit and side: --output-unit rad|deg|rev|m|mm, "
                         "--output-side motor|arm)");
    }
  }
  if (arm) {
    if (!m.armUnit)
      warnings.push_back("the arm angle " + found.armSource + " is taken in rad: its unit was not given (--arm-unit)");
    const SignalUnit u = m.armUnit.value_or(SignalUnit::Rad);
    scale(*arm, toSiFactor(u));
    if (!rename(*arm, columns::kArmAngle, "rad", found.armSource)) return false;
  }
  if (ref) {
    // A position reference in the output's unit and on its side; a velocity output says
    // nothing of a position's unit, so the reference is then read as stored.
    const SignalUnit u = m.outputUnit.value_or(SignalUnit::Rad);
    if (m.convertsOutput() && !isVelocity(u)) {
      scale(*ref, outputFactor);
      if (!rename(*ref, isLinear(u) ? columns::kPositionRef : columns::kAngleRef, isLinear(u) ? "m" : "rad",
                  found.referenceSource))
        return false;
    } else if (foreign) {
      warnings.push_back("the reference " + found.referenceSource +
                         " is read as stored: it takes the output's unit and side, and those were not given "
                         "as a position's");
    }
    for (Channel& c : data.channels)
      if (c.role == ChannelRole::Reference) c.role = ChannelRole::None;
    ref->role = ChannelRole::Reference;
  }
  // Roles after the names: the mapped input and output are the only ones.
  if (in) data.setRole(in->name, ChannelRole::Input);
  if (out) data.setRole(out->name, ChannelRole::Output);
  if (arm && arm->role != ChannelRole::None) arm->role = ChannelRole::None;
  if (ratio > 0.0) {
    data.setMeta("gear_ratio", number(ratio));
  } else if (m.convertsOutput() && !prismatic && data.meta("gear_ratio").empty()) {
    warnings.push_back("no gear ratio was given (--gear-ratio, arm/motor, e.g. 1/256.86): a physical "
                       "model keeps its own");
  }
  if (m.convertsOutput()) data.setMeta("axis", prismatic ? "prismatic" : "rotary");
  if (const auto d = describeMapping(m); !d.empty()) data.setMeta("import", join(d, "; "));
  if (!warnings.empty()) data.setMeta("assumed", join(warnings, "; "));
  return true;
}

}  // namespace flexarm
