#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_MODELS_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_MODELS_H_

// MJCF models built into the binary, authored for vantage from the facts
// (bodies, joint ranges, gears, masses, timesteps) of the Gymnasium v4
// MuJoCo tasks; loaded through MuJoCo's virtual file system. Each is a file
// in assets/ (snake_case.xml defines kSnakeCaseXml), embedded at build time
// by assets/embed.cmake.

namespace vantage {

extern const char kInvertedPendulumXml[];
extern const char kInvertedDoublePendulumXml[];
extern const char kHalfCheetahXml[];
extern const char kHopperXml[];
extern const char kWalker2dXml[];
extern const char kAntXml[];
extern const char kHumanoidXml[];
extern const char kPointMazeXml[];
extern const char kTwoDMazeXml[];

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_MODELS_H_
