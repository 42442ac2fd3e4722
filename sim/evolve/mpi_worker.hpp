// SPDX-License-Identifier: Apache-2.0
#pragma once
// What every rank but 0 does in an MPI run: serve evaluations. It waits for rank 0's
// setup, builds the scorer from it, answers with its thread count, then evaluates
// the teams it is handed (one per thread at a time) and sends each score back,
// until rank 0 says stop. It keeps no state of the run, so a resumed run needs
// nothing from it.
#include <functional>

#include "sim/evolve/evaluator.hpp"
#include "sim/evolve/mpi_session.hpp"
#include "sim/evolve/mpi_wire.hpp"

namespace tensegrity::sim::evolve {

// Turns a setup into the scorer; throws on a setup it cannot serve (the message
// goes back to rank 0, which reports it).
using TeamFunctionFactory = std::function<TeamFunction(const wire::Setup& setup)>;

// Returns when rank 0 says stop. Throws MpiFailure on an MPI error or a message
// outside the protocol. A later setup replaces the scorer (tests run several
// evaluators in one job).
void serve_evaluations(MpiSession& session, int threads, const TeamFunctionFactory& factory);

}  // namespace tensegrity::sim::evolve
