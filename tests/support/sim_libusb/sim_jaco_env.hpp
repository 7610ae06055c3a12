#pragma once
/// @file
/// @brief The simulated Kinova JACO arms of the libusb-1.0 shim (sim_libusb.cpp), read from the
/// environment, and shared with the tests that check what a libusb program saw (they build the
/// same SimJacoConfig from the same string).
///
/// ORTHOFLOW_SIM_JACO: unset, empty or "0" = no arm (the shim then hosts Kinects only). Otherwise
/// arms separated by ';', each either "1" or empty (every default) or a ','-separated list of
/// key=value (whitespace around tokens is ignored):
///   model=jaco2|v1        (jaco2: SimJacoConfig{}, DSP 5.2; v1: sim_jaco_v1_config(), DSP 4.2;
///                          applied first, whatever its place in the list)
///   state=noinit|normal|ready|retract   (power-up state; the pose follows SimJacoConfig's rule:
///                          HOME for ready, RETRACT otherwise)
///   serial=<1..19 chars>  name=<1..19 chars>   (the client-info serial and client name)
///   usb_serial=<1..126 chars>   (the USB iSerialNumber; default none, as SimJacoTransport)
///   bus=<1..255>          port=<1..15>   (its root-hub port)
///   stale=<n>             (stale replies queued at power-up: the driver's flush must eat them)
///   drop_out=|in_timeout=|garbage=|corrupt=|wrong_command=<rate in [0, 1]>   fault_seed=<u64>
///   never_leave_noinit=0|1    fw5_quirk=0|1   (SimJacoFaults' switches)
/// Arm k (from 0) defaults to the model's serial for k = 0 and to it with its last character
/// replaced by hex digit k otherwise, to name "sim-jaco" (k = 0) or "sim-jaco-<k>", to bus 1 and to
/// the lowest root-hub port of its bus that no Kinect hub (ORTHOFLOW_SIM_KINECT) and no earlier arm
/// uses. Anything else (unknown key, bad number, a port already taken) is an error.
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "simulation/devices/sim_jaco_arm.hpp"
#include "simulation/devices/sim_kinect_device.hpp"

namespace orthoflow::sim_libusb {

inline constexpr const char* ENV_JACO = "ORTHOFLOW_SIM_JACO";

/// @brief The arms @p text describes (syntax above), placed beside @p kinects (their hubs' root
/// ports are taken). @return a message naming the bad token. @note Allocates; no exceptions escape.
[[nodiscard]] Result<std::vector<simulation::SimJacoConfig>, std::string> parse_jacos(
    std::string_view text, const std::vector<simulation::SimKinectConfig>& kinects = {});

/// @brief parse_jacos of getenv(ENV_JACO) (unset = empty).
[[nodiscard]] Result<std::vector<simulation::SimJacoConfig>, std::string> jacos_from_env(
    const std::vector<simulation::SimKinectConfig>& kinects);

}  // namespace orthoflow::sim_libusb
