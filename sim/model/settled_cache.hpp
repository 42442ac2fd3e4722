// SPDX-License-Identifier: Apache-2.0
#pragma once
// The cache behind settled_state (episode.hpp): one settled start per robot hash and
// time step. Models drawn afresh every generation (robust learning) drop the starts
// of the models they will not play again, so that the cache does not grow with every
// model ever drawn.
#include <cstddef>

#include "robot/robot.hpp"

namespace tensegrity::sim {

// Drops the robot's settled start at that step (0: its own step). No reference to it
// may be in use.
void forget_settled_state(const Robot& robot, double dt_s);
// How many settled starts the cache holds.
std::size_t settled_states_cached();

}  // namespace tensegrity::sim
