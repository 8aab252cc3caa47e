#ifndef VANTAGE_BENCH_TRANSPORT_BENCH_H_
#define VANTAGE_BENCH_TRANSPORT_BENCH_H_

// Benchmarks of the actor-learner data path over loopback gRPC, each
// against a baseline measured in the same run.

#include <string>

#include "common/nn/network_config.h"

namespace vantage {

// `vantage bench ingest`: K clients stream HalfCheetah-sized segments (128
// steps of one env slot, real data from an actor) as fast as they can into
// a learner that only ingests (service, validation, queue, stitching); the
// learner's env steps/s over the window, against one actor's own rate (an
// actor core with 16 HalfCheetah envs and batched inference, no transport),
// both over `seconds` split into windows, the fastest window kept.
// Ends with `RESULT ingest clients=K steps_per_s=<x> actor_steps_per_s=<y>
// actors_fed=<x/y>`. Returns the exit code.
int RunIngestBenchmark(int clients, double seconds);

// `vantage bench actor --env=NAME --envs=M`: the env steps/s of the
// `vantage actor` loop (M envs, batched inference on one thread, segments
// of 128 steps streamed over loopback gRPC to a learner that only ingests
// and publishes a version per horizon of its data), over `seconds` split
// into windows, the fastest kept, against the bare physics of the env's
// model on one core (`bench env`'s raw figure, measured in the same run).
// The policy is `network` (64x64 tanh layers, and its recurrent core if
// any, whose state the actor carries and sends). Ends with `RESULT actor
// env=NAME envs=M core=C raw_steps_per_s=<x> actor_steps_per_s=<y>
// ratio=<y/x>`. Returns the exit code.
int RunActorBenchmark(const std::string& env_name, int envs, double seconds,
                      const NetworkConfig& network);

// `vantage bench connections`: what connected actors cost a learner. A
// `vantage learner` process (InvertedPendulum, a batch that never
// completes) against its own idle footprint measured in the same run:
// `max_actors` loopback clients register, each sends one real 128-step
// segment and holds its stream open; the learner's RSS and threads at a
// quarter, half, three quarters and all of them. Ends with `RESULT
// connections actors=N idle_rss_mb=.. rss_mb=.. per_actor_kb=..
// threads=.. idle_threads=..`.
int RunConnectionsBenchmark(int max_actors);

}  // namespace vantage

#endif  // VANTAGE_BENCH_TRANSPORT_BENCH_H_
