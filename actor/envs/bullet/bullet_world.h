#ifndef VANTAGE_ACTOR_ENVS_BULLET_BULLET_WORLD_H_
#define VANTAGE_ACTOR_ENVS_BULLET_BULLET_WORLD_H_

// A planar articulated body of capsules and boxes on a (possibly tilted)
// ground plane,
// simulated with Bullet's Featherstone multibody. Everything Bullet
// allocates is owned here and released in the order Bullet needs.
//
// The body moves in the x-z plane: a fixed base carries a massless-in-effect
// x slide, a z slide on it, and the root link hinged about +y on that, so the
// generalised coordinates are q = (x, z, pitch, joint 1, ..., joint n-1) with
// (x, z) the root point and pitch the root link's rotation about +y
// (positive leans the top forward, towards +x), exactly like MuJoCo's
// rootx/rootz/rooty joints.

#include <memory>
#include <string>
#include <vector>

#include "BulletDynamics/Featherstone/btMultiBody.h"
#include "BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h"
#include "BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h"
#include "BulletDynamics/Featherstone/btMultiBodyGearConstraint.h"
#include "BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h"
#include "BulletDynamics/Featherstone/btMultiBodyLinkCollider.h"
#include "absl/status/status.h"
#include "absl/types/span.h"
#include "btBulletCollisionCommon.h"
#include "btBulletDynamicsCommon.h"

namespace vantage {

// One capsule of the body, given in world coordinates (metres, radians) at
// the zero pose, where every coordinate of q but z is 0.
struct PlanarLink {
  std::string name;
  // An earlier link; -1 for link 0 (the root) and only for it.
  int parent = -1;
  // The capsule's segment, parallel to x or to z (its inertia is then
  // diagonal in world axes), and its radius.
  double from_x = 0.0;
  double from_z = 0.0;
  double to_x = 0.0;
  double to_z = 0.0;
  double radius = 0.05;
  // Bullet multiplies the two frictions of a contact; the ground has 1.
  double friction = 0.9;
  // The hinge to the parent (unused for the root): its point, its axis
  // (0, axis, 0) with axis +1 or -1, its range, a viscous damping applied
  // as a torque each physics step, and a rotor inertia in joint space
  // (MuJoCo's armature: kinetic energy armature * qdot^2 / 2, its reaction
  // taken by the world), simulated as a rotor on the fixed base geared 1:1
  // to the hinge.
  double joint_x = 0.0;
  double joint_z = 0.0;
  double axis = 1.0;
  double lower = 0.0;
  double upper = 0.0;
  double damping = 0.0;
  double armature = 0.0;
  // A box instead of a capsule when box_width > 0: its full sizes along x
  // (width), y (depth) and z (height) at the zero pose and its centre there;
  // from_/to_ and radius are then unused.
  double box_width = 0.0;
  double box_depth = 0.0;
  double box_height = 0.0;
  double box_centre_x = 0.0;
  double box_centre_z = 0.0;
  // > 0: the link's mass (kg) rather than the model's density times its
  // volume.
  double mass = 0.0;

  bool is_box() const { return box_width > 0.0; }
};

struct PlanarModel {
  std::vector<PlanarLink> links;
  // Height of the root point at the zero pose (its x is 0).
  double root_z = 1.0;
  // Masses from the capsules' volumes.
  double density = 1000.0;
  // The ground plane passes through the origin and rises by tan(slope) per
  // metre of x (radians; 0 is flat).
  double slope = 0.0;
  // If not empty, the ground is this height profile instead of the plane:
  // heights (m) at x = ground_start_x + i * ground_spacing, joined by
  // straight segments and extended level past both ends.
  std::vector<double> ground_heights;
  double ground_start_x = 0.0;
  double ground_spacing = 0.0;
  double gravity = 9.81;
  // Physics timestep (seconds) and sequential-impulse iterations.
  double timestep = 0.002;
  int solver_iterations = 10;
};

// Where a link's capsule is now: its segment's end points in the x-z
// plane and its radius (metres), for pictures.
struct CapsulePose {
  double from_x = 0.0;
  double from_z = 0.0;
  double to_x = 0.0;
  double to_z = 0.0;
  double radius = 0.0;
};

// Checks what BulletWorld relies on; the message names the link.
absl::Status ValidatePlanarModel(const PlanarModel& model);

class BulletWorld {
 public:
  // `model` must pass ValidatePlanarModel. The body starts at the zero pose
  // (root point at (0, root_z)) at rest.
  explicit BulletWorld(const PlanarModel& model);
  ~BulletWorld();
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  // 3 root coordinates + one per hinge.
  int num_dofs() const { return num_dofs_; }
  double q(int i) const;
  double qd(int i) const;
  // Sets positions and velocities (num_dofs each) and moves the colliders
  // there.
  void SetState(absl::Span<const double> q, absl::Span<const double> qd);
  // `substeps` physics steps with the hinge torques (N m, one per hinge)
  // held, minus each hinge's damping times its velocity of the moment.
  void Step(absl::Span<const double> torques, int substeps);

  // Rotation about +y of link `link` in the world (root pitch plus the
  // signed hinge angles down to it).
  double LinkPitch(int link) const;
  // Whether link `link` touched the ground in the last physics step.
  bool TouchesGround(int link) const;
  // Height of the ground plane at `x`.
  double GroundHeight(double x) const;
  // Positions and velocities are all finite.
  bool IsFinite() const;
  double LinkMass(int link) const;
  int num_links() const { return static_cast<int>(colliders_.size()); }
  // Read from the link's collider, as the last physics step or SetState
  // left it. A box is drawn as the capsule of its footprint: its long
  // side's centre line, rounded to half its short side.
  CapsulePose LinkCapsule(int link) const;

 private:
  // The constructor's steps, in order: the dynamics world, the ground, the
  // multibody (its links and their shapes), the links' colliders, and the
  // joint limits and rotor gears.
  void CreateDynamicsWorld(const PlanarModel& model);
  void CreateGround(const PlanarModel& model);
  void CreateBody(const PlanarModel& model, int rotors);
  static std::unique_ptr<btCollisionShape> LinkShape(const PlanarLink& link);
  void AddColliders(const PlanarModel& model);
  void AddJointConstraints(const PlanarModel& model);

  // Bullet's link index of q(i), and of link `link`.
  static int DofLink(int i) { return i; }
  static int LinkIndex(int link) { return link + 2; }

  int num_dofs_ = 0;
  double slope_tangent_ = 0.0;
  std::vector<double> ground_heights_;
  double ground_start_x_ = 0.0;
  double ground_spacing_ = 0.0;
  double timestep_ = 0.0;
  std::vector<double> damping_;           // per hinge
  std::vector<std::vector<int>> chains_;  // per link: hinges root..link
  std::vector<double> axes_;              // per hinge
  std::vector<int> rotors_;  // per hinge: its rotor's Bullet link, or -1

  // Destroyed bottom-up: the world (which still reads its objects, the
  // broadphase and the dispatcher while it dies) goes first, once the
  // destructor has taken every object out of it.
  std::unique_ptr<btDefaultCollisionConfiguration> collision_config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btMultiBodyConstraintSolver> solver_;
  std::unique_ptr<btTriangleMesh> ground_mesh_;  // a profile's, or null
  std::unique_ptr<btCollisionShape> ground_shape_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::unique_ptr<btMultiBody> body_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>> limits_;
  std::vector<std::unique_ptr<btMultiBodyGearConstraint>> gears_;
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_BULLET_WORLD_H_
