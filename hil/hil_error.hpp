// SPDX-License-Identifier: Apache-2.0
// The one exception the HIL throws: a run that cannot go on (a missing end cap, a
// failed boot, a bad scenario). The message names what failed, so the launcher
// prints it as the reason for its non-zero exit.
#pragma once

#include <stdexcept>

namespace tensegrity::hil {

class HilError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The DDS link did not come up for every end cap before the start: nothing has moved,
// so run_hil may start every process again (HilOptions::link_attempts).
class LinkDownError : public HilError {
 public:
  using HilError::HilError;
};

}  // namespace tensegrity::hil
