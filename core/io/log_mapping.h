#pragma once
// Which signal of a foreign log is what, in which unit and on which side of the gear: the one
// description that the command line (--time-var, --input-var, --output-var, --arm-var,
// --ref-var, --output-unit, --arm-unit, --output-side, --gear-ratio, --input-scale), the window's import
// dialog and the session share. Reading applies it once: the input becomes torque_ref_nm
// (N m at the motor; force_ref_n for a prismatic axis), the output the motor shaft's angle in
// rad (motor_angle_rad; motor_velocity_rad_s for a velocity, motor_position_m and
// motor_velocity_m_s for a prismatic axis), the arm encoder arm_angle_rad (the arm side, not
// scaled to the motor), a position reference angle_ref_rad (position_ref_m) converted as the
// output is; the gear ratio is stored as the log's gear_ratio. Nothing is guessed:
// what was not said is named in a warning.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/signal/id_data.h"

namespace flexarm {

namespace columns {
// A prismatic axis: the input force and the motor's (load's) position and velocity.
inline constexpr const char* kForceRef = "force_ref_n";
inline constexpr const char* kMotorPosition = "motor_position_m";
inline constexpr const char* kMotorLinearVelocity = "motor_velocity_m_s";
inline constexpr const char* kPositionRef = "position_ref_m";
}  // namespace columns

// The unit a position or velocity is stored in. Angles and angular velocities belong to a
// rotary axis, lengths to a prismatic one.
enum class SignalUnit { Rad, Deg, Rev, RadPerS, DegPerS, Rpm, M, Mm, MPerS, MmPerS };
const char* toString(SignalUnit u);  // "rad", "deg", "rev", "rad/s", "deg/s", "rpm", "m", ...
std::optional<SignalUnit> signalUnitFromString(std::string_view s);
// The factor to SI (rad, rad/s, m, m/s): 1 rev = 2 pi rad, 1 rpm = 2 pi / 60 rad/s.
double toSiFactor(SignalUnit u);
bool isLinear(SignalUnit u);
bool isVelocity(SignalUnit u);

// The side of the gear a motor encoder's value is given on: the motor shaft, or scaled to the
// arm (as KUKA and many controllers store it: motor angle = value / gear ratio).
enum class EncoderSide { Motor, Arm };
const char* toString(EncoderSide s);
std::optional<EncoderSide> encoderSideFromString(std::string_view s);

// A gear ratio arm/motor as the log's gear_ratio metadata: "0.00389", "1/256.86". nullopt with
// a sentence unless positive and finite.
std::optional<double> parseGearRatio(std::string_view text, std::string* why);

// The ratio written the other way round: "256.86" -> "1/256.86", "1/118" -> "118",
// "10/3" -> "3/10". For a gear ratio given as datasheets give it (motor turns per arm turn),
// which a mapping refuses (above 1) and the dialog and the command line offer inverted. Empty
// when the text is not a positive ratio.
std::string invertedGearRatio(std::string_view text);

struct LogMapping {
  // Where each signal is: a MATLAB expression in a .mat file (rec.act_torque_abs_nm(1,:)), a
  // header name in a CSV file (torque_motor_Nm), "column N" in a headerless table. Empty:
  // the format's own (time_s, torque_ref_nm, motor_angle_rad, ...). The reference (a closed
  // loop's position reference) is in the output's unit and on its side.
  std::string time, input, output, arm, reference;
  std::optional<SignalUnit> outputUnit, armUnit;
  std::optional<EncoderSide> outputSide;
  std::string gearRatio;   // as given ("1/256.86"); empty: not given
  double inputScale = 1.0; // the input times this is the torque in N m (force in N)

  // False with a sentence for what cannot be read as said, among them a gear ratio above 1 (the
  // arm faster than the motor: a gear ratio typed motor/arm, which would scale an arm-side
  // angle the wrong way by the ratio squared); the sentence then names the inverse.
  bool isValid(std::string* why) const;
  // True when the units of the output are said (the output is converted and renamed).
  bool convertsOutput() const { return outputUnit.has_value() || outputSide.has_value(); }
  bool operator==(const LogMapping& o) const;
  bool operator!=(const LogMapping& o) const { return !(*this == o); }
};

// The mapping in a few phrases for a result's provenance and the log's metadata, e.g.
// {"input torque_ref_nm = rec.act_torque_abs_nm(1,:)", "output motor_angle_rad =
// rec.act_pos_mot_deg(1,:) in deg on the arm side, times 256.86 (gear ratio 1/256.86)"};
// empty when nothing is mapped or converted.
std::vector<std::string> describeMapping(const LogMapping& m);

// The channels a reader found for the mapping: indices into data.channels (-1: none) and the
// text that named them (an expression, a header name, "column 3").
struct MappedChannels {
  int input = -1, output = -1, arm = -1, reference = -1;
  std::string inputSource, outputSource, armSource, referenceSource;
};

// Applies the mapping to the channels a reader found: scales the input, converts the output
// and arm units and sides, names them as FlexArm does, gives them their roles, and records the
// gear ratio, the axis kind (metadata axis: rotary | prismatic), what was converted (metadata
// import) and what was assumed (metadata assumed, and warnings). `foreign`: the file does not
// name its signals FlexArm's way (a .mat file, a table, a CSV with other names), so an output
// without a stated unit is a warning. False with a sentence when the mapping cannot hold
// (an arm side without a gear ratio, a channel name taken twice).
bool applyMapping(IdData& data, const MappedChannels& found, const LogMapping& m, bool foreign,
                  std::vector<std::string>& warnings, std::string* why);

}  // namespace flexarm
