#pragma once
// Input-output data set of one robot axis, in the spirit of SITB's iddata: uniformly sampled
// named channels with units and roles, metadata, and the estimation and validation ranges.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace flexarm {

// Column names of the FlexArm CSV log (shared/notes/log-format.md).
namespace columns {
inline constexpr const char* kTime = "time_s";
inline constexpr const char* kTorqueRef = "torque_ref_nm";
inline constexpr const char* kMotorAngle = "motor_angle_rad";
inline constexpr const char* kMotorVelocity = "motor_velocity_rad_s";
inline constexpr const char* kAngleRef = "angle_ref_rad";
inline constexpr const char* kArmAccel = "arm_accel_rad_s2";
// A secondary, arm-side encoder: the arm angle itself (not scaled to the motor side).
inline constexpr const char* kArmAngle = "arm_angle_rad";
// Motor or gearbox temperature.
inline constexpr const char* kTemperature = "temperature_c";
}  // namespace columns

enum class ChannelRole { None, Input, Output, Reference };
const char* toString(ChannelRole r);
std::optional<ChannelRole> channelRoleFromString(std::string_view s);

// Display unit for a column name whose unit is its suffix ("motor_angle_rad" -> "rad",
// "arm_accel_rad_s2" -> "rad/s^2"); empty when the suffix is not a known unit.
std::string unitFromColumnName(std::string_view name);

struct Channel {
  std::string name;  // column name, unit suffix included, e.g. "torque_ref_nm"
  std::string unit;  // display unit, e.g. "N m"
  ChannelRole role = ChannelRole::None;
  std::vector<double> values;
};

// Half-open range of sample indices [begin, end).
struct SampleRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t size() const { return end > begin ? end - begin : 0; }
  bool empty() const { return size() == 0; }
  bool operator==(const SampleRange& o) const { return begin == o.begin && end == o.end; }
};

class IdData {
 public:
  // The finest sample time FlexArm handles (1 MHz): its logs hold time with 9 decimals.
  static constexpr double kMinSampleTime = 1e-6;
  double sampleTime = 1.0;  // seconds between samples
  double startTime = 0.0;   // time of sample 0, seconds
  std::vector<Channel> channels;
  std::vector<std::pair<std::string, std::string>> metadata;  // in file order
  std::optional<SampleRange> estimationRange;
  std::optional<SampleRange> validationRange;
  // Sampling instants of data that are not uniformly sampled (as SITB's SamplingInstants), one
  // per sample in file order, with the file line of each (when read from a file); empty for
  // uniform data, whose sample i lies at startTime + i sampleTime. Only reading with
  // LogReadOptions::keepIrregularTime makes such data, and resampleToUniform
  // (uniform_grid.h) is the step that turns them into uniform data; sampleTime is then the
  // nominal interval. A NaN value marks a channel that was not sampled at that instant
  // (channels logged at different rates).
  std::vector<double> timeStamps;
  std::vector<int> sourceLines;

  std::size_t samples() const { return channels.empty() ? 0 : channels.front().values.size(); }
  double sampleRateHz() const { return 1.0 / sampleTime; }
  double duration() const { return samples() == 0 ? 0.0 : (samples() - 1) * sampleTime; }
  double timeAt(std::size_t i) const {
    return timeStamps.empty() ? startTime + static_cast<double>(i) * sampleTime : timeStamps[i];
  }
  bool isUniform() const { return timeStamps.empty(); }

  int indexOf(std::string_view name) const;
  const Channel* channel(std::string_view name) const;
  Channel* channel(std::string_view name);
  // First channel with the role, or nullptr.
  const Channel* withRole(ChannelRole role) const;
  const Channel* input() const { return withRole(ChannelRole::Input); }
  const Channel* output() const { return withRole(ChannelRole::Output); }
  // Makes the named channel the only one with this role (Input or Output); false if absent.
  bool setRole(std::string_view name, ChannelRole role);
  // True when a reference channel is present: the data were logged in closed loop.
  bool isClosedLoop() const { return withRole(ChannelRole::Reference) != nullptr; }

  // Appends or replaces a channel; values must have samples() entries unless it is the first.
  void setChannel(Channel c);

  std::string meta(std::string_view key) const;  // empty when absent
  void setMeta(const std::string& key, const std::string& value);

  // The samples whose time lies in [t0, t1], clipped to the data.
  SampleRange rangeForTimes(double t0, double t1) const;
  // The sample nearest to time t (the first at or after t among time stamps, which are
  // searched as if sorted); 0 for empty data.
  std::size_t indexNear(double t) const;
  // A copy holding only the samples in r; ranges are shifted and clipped to it.
  IdData select(SampleRange r) const;

  // True when every channel has the same length, every value is finite (or, for data with
  // time stamps, NaN where a channel was not sampled), the time stamps are finite and the
  // sample time is finite and at least kMinSampleTime; otherwise says why.
  bool isValid(std::string* why = nullptr) const;
};

}  // namespace flexarm
