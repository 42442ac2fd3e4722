// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fixed capacities and per-motor limits of the control core. The core has no heap
// after construction, so every table it holds has a compile-time bound.
#include <cstddef>
#include <cstdint>

namespace tensegrity::core {

inline constexpr std::size_t kMaxMotorsPerEndcap = 4;
inline constexpr std::size_t kMaxComplexity = 16;

// What a motor does while its cable is above the cut-off tension.
enum class Overload : std::uint8_t {
  hold,     // stop shortening, keep the length (the hardware guard, docs/design/robot.md)
  pay_out,  // give cable at the motor speed until the tension is back under the cut-off: the
            // paper's back-driven motor that feeds out cable (Iscen et al., section 3), and
            // NTRT's muscle, whose moveMotors raises the preferred length to keep k (L - L0)
            // at maxTens (tgLinearString.cpp, 2014)
};

struct MotorLimits {
  double min_rest_length_m = 0.6;
  double max_rest_length_m = 1.1;
  double speed_m_per_s = 0.2;
  // Above this the motor stops shortening (it may still pay out cable).
  double cutoff_tension_n = 400.0;
  // Above this the end cap faults and holds until the fault is cleared.
  double hard_limit_tension_n = 500.0;
  Overload overload = Overload::hold;
};

enum class LimitsError : std::uint8_t {
  none = 0,
  not_positive,             // a limit is zero, negative or not finite
  empty_rest_length_range,  // max_rest_length_m is not above min_rest_length_m
  hard_limit_below_cutoff,  // the end cap would fault before the motor stops pulling
};

// The one check of a set of limits, for the end cap's config and the robot files.
LimitsError validate(const MotorLimits& limits) noexcept;
// Static text for errors, naming the fields by their MotorLimits names.
const char* describe(LimitsError error) noexcept;
// The MotorLimits field an error is reported at ("max_rest_length_m", ...).
const char* field_of(LimitsError error) noexcept;

// "hold" / "pay_out": the one spelling of Overload in robot files and end-cap configs,
// in the order of the enum.
inline constexpr const char* kOverloadNames[] = {"hold", "pay_out"};
const char* to_string(Overload overload) noexcept;

}  // namespace tensegrity::core
