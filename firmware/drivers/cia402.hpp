// SPDX-License-Identifier: Apache-2.0
// CiA 402 drive profile: the power state machine as the statusword (0x6041)
// reports it, and the controlword (0x6040) commands that move it. Pure functions,
// shared by the master's drive client and emulated drives.
#pragma once

#include <cstdint>
#include <optional>

namespace tensegrity::fw::canopen {

// Object dictionary entries of the drive we use.
inline constexpr std::uint16_t kOdControlword = 0x6040;
inline constexpr std::uint16_t kOdStatusword = 0x6041;
inline constexpr std::uint16_t kOdModesOfOperation = 0x6060;
inline constexpr std::uint16_t kOdModesOfOperationDisplay = 0x6061;
inline constexpr std::uint16_t kOdPositionActual = 0x6064;
inline constexpr std::uint16_t kOdVelocityActual = 0x606C;
inline constexpr std::uint16_t kOdTargetPosition = 0x607A;
inline constexpr std::int8_t kModeCyclicSynchronousPosition = 8;
// Communication cycle period (CiA 301, UNSIGNED32, microseconds): the SYNC period.
inline constexpr std::uint16_t kOdCommunicationCyclePeriod = 0x1006;
// Interpolation time period (CiA 402): sub 1 the value (UNSIGNED8), sub 2 the index
// (INTEGER8), value x 10^index seconds: the period at which CSP targets arrive.
inline constexpr std::uint16_t kOdInterpolationTimePeriod = 0x60C2;
struct InterpolationPeriod {
  std::uint8_t value = 1;
  std::int8_t index = -3;
};
// The period as 0x60C2 says it, in its shortest form as drives' manuals write it
// (1 ms: 1 x 10^-3); none when it cannot (not a value <= 255 times 10^index s,
// index -9..0).
std::optional<InterpolationPeriod> interpolation_period(std::int64_t period_ns);
// The period 0x60C2 says, in ns; -1 for an index outside -9..0.
std::int64_t period_ns(InterpolationPeriod period);
// Abort connection option code (INTEGER16): what the drive does by itself when it
// loses its master (a heartbeat it consumes through 0x1016 times out).
inline constexpr std::uint16_t kOdAbortConnectionOption = 0x6007;
enum class AbortConnectionOption : std::int16_t {
  no_action = 0,
  fault_signal = 1,     // the drive goes to fault
  disable_voltage = 2,  // power stage off: the motor coasts (or its brake holds)
  quick_stop = 3,       // decelerate on the quick-stop ramp, then hold
};

enum class Cia402State : std::uint8_t {
  not_ready_to_switch_on,
  switch_on_disabled,
  ready_to_switch_on,
  switched_on,
  operation_enabled,
  quick_stop_active,
  fault_reaction_active,
  fault,
  invalid,  // statusword bits match no state
};

enum class Cia402Command : std::uint8_t {
  shutdown,           // -> ready to switch on
  switch_on,          // -> switched on
  enable_operation,   // -> operation enabled (also from switched on)
  disable_operation,  // operation enabled -> switched on
  disable_voltage,    // -> switch on disabled
  quick_stop,         // operation enabled -> quick stop active
  fault_reset,        // fault -> switch on disabled, on the 0->1 edge of bit 7
};

// Statusword bits beyond the state.
inline constexpr std::uint16_t kSwVoltageEnabled = 1U << 4;
inline constexpr std::uint16_t kSwWarning = 1U << 7;
inline constexpr std::uint16_t kSwRemote = 1U << 9;
inline constexpr std::uint16_t kSwTargetReached = 1U << 10;
inline constexpr std::uint16_t kSwFollowingError = 1U << 13;
inline constexpr std::uint16_t kCwFaultReset = 1U << 7;

const char* to_string(Cia402State state);
const char* to_string(Cia402Command command);

Cia402State decode_statusword(std::uint16_t statusword);
// The state bits a drive reports (others zero), for emulated drives.
std::uint16_t statusword_bits(Cia402State state);
std::uint16_t controlword_bits(Cia402Command command);
// What a drive makes of a controlword, by the bits CiA 402 table 48 reads.
// Fault reset is reported only when bit 7 is set; the edge is the drive's concern.
bool decode_controlword(std::uint16_t controlword, Cia402Command& command);

// What the master asks of the drive.
enum class PowerRequest : std::uint8_t {
  disabled,           // voltage off, motor free
  operation_enabled,  // follow the target position
  quick_stop,         // stop now, then hold in quick stop
};

}  // namespace tensegrity::fw::canopen
