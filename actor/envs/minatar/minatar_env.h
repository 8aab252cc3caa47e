#ifndef VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_ENV_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_ENV_H_

// The MinAtar games as environments: MinAtar's six actions (noop, left,
// up, right, down, fire; a game ignores those it has no use for), sticky
// actions (with probability 0.1 the previous action is repeated instead,
// drawn from the game's own generator before the game's draws, as MinAtar
// does), difficulty ramping on, and the [channels, 10, 10] grid of zeros
// and ones as the observation. Episodes end when the game does (Freeway
// after 2500 steps) or after 10000 steps; an episode starts from its seed
// alone (the repeated action starts as noop).

#include <memory>

#include "absl/status/statusor.h"
#include "actor/envs/minatar/minatar_game.h"
#include "common/env/environment.h"

namespace vantage {

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarAsterix();
absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarBreakout();
absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarFreeway();
absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarSeaquest();
absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarSpaceInvaders();

// A fresh copy of the bare game under `env` (a MinAtar environment, or a
// wrapper's inner one), for benchmarks; nullptr for any other environment.
std::unique_ptr<MinAtarGame> MakeBareGame(const Environment& env);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_ENV_H_
