#include "deploy/run/launcher.h"

#include <cstdint>
#include <set>

#include "gtest/gtest.h"

namespace vantage {
namespace {

// An actor's first life keeps the seed it always had (run seed + actor, so
// one actor repeats a local run); every restart gets a seed no other life of
// any actor of the run has.
TEST(LauncherTest, EachLifeOfAnActorHasItsOwnSeed) {
  for (uint64_t run_seed : {uint64_t{0}, uint64_t{7}, ~uint64_t{0}}) {
    std::set<uint64_t> seeds;
    for (int actor = 0; actor < 64; ++actor) {
      EXPECT_EQ(ActorLifeSeed(run_seed, actor, 0), run_seed + actor);
      for (int life = 0; life < 64; ++life) {
        seeds.insert(ActorLifeSeed(run_seed, actor, life));
      }
    }
    EXPECT_EQ(seeds.size(), 64u * 64u) << run_seed;
  }
  // The same life of the same actor, the same seed: a rerun repeats it.
  EXPECT_EQ(ActorLifeSeed(3, 1, 5), ActorLifeSeed(3, 1, 5));
}

}  // namespace
}  // namespace vantage
