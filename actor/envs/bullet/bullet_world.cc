#include "actor/envs/bullet/bullet_world.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The slides carry no real body; Bullet wants a positive mass and inertia.
constexpr double kSlideMass = 1e-3;
constexpr double kSlideInertia = 1e-5;
// The collision margin of a box, inside its faces, and of a ground profile.
constexpr double kBoxMargin = 2e-3;
// A ground profile spans y in [-kGroundHalfWidth, kGroundHalfWidth] and
// stays level for kRunOut metres past its ends.
constexpr double kGroundHalfWidth = 1.0;
constexpr double kRunOut = 100.0;
// Manifold points closer than this count as touching.
constexpr double kTouchDistance = 2e-3;
// Link colliders only meet the ground, never each other.
constexpr int kBodyGroup = btBroadphaseProxy::DefaultFilter;
constexpr int kGroundGroup = btBroadphaseProxy::StaticFilter;

bool AlongX(const PlanarLink& link) { return link.from_z == link.to_z; }

double SegmentLength(const PlanarLink& link) {
  return std::hypot(link.to_x - link.from_x, link.to_z - link.from_z);
}

struct CapsuleInertia {
  double mass;
  double axial;          // about the segment
  double perpendicular;  // about an axis through the centre across it
};

// A cylinder of length `length` capped by two hemispheres of `radius`.
CapsuleInertia Capsule(double length, double radius, double density) {
  const double r2 = radius * radius;
  const double cylinder = density * kPi * r2 * length;
  const double hemisphere = density * 2.0 / 3.0 * kPi * r2 * radius;
  CapsuleInertia inertia;
  inertia.mass = cylinder + 2.0 * hemisphere;
  inertia.axial = cylinder * r2 / 2.0 + 2.0 * hemisphere * 2.0 * r2 / 5.0;
  // Each hemisphere about its flat face's diameter is 2/5 m r^2; shifted to
  // the capsule's centre, its own centre sits 3r/8 beyond the face.
  inertia.perpendicular = cylinder * (length * length / 12.0 + r2 / 4.0) +
                          2.0 * hemisphere *
                              (2.0 * r2 / 5.0 + length * length / 4.0 +
                               3.0 * length * radius / 8.0);
  return inertia;
}

// A link's mass, its inertia about its centre (x, y, z world axes at the
// zero pose) and its centre there.
struct LinkInertia {
  double mass;
  btVector3 inertia;
  btVector3 centre;
};

LinkInertia InertiaOf(const PlanarLink& link, double density) {
  LinkInertia result;
  if (link.is_box()) {
    const double w2 = link.box_width * link.box_width;
    const double d2 = link.box_depth * link.box_depth;
    const double h2 = link.box_height * link.box_height;
    result.mass = link.mass > 0.0 ? link.mass
                                  : density * link.box_width * link.box_depth *
                                        link.box_height;
    result.inertia = btVector3(result.mass * (d2 + h2) / 12.0,
                               result.mass * (w2 + h2) / 12.0,
                               result.mass * (w2 + d2) / 12.0);
    result.centre = btVector3(link.box_centre_x, 0, link.box_centre_z);
    return result;
  }
  const CapsuleInertia capsule =
      Capsule(SegmentLength(link), link.radius, density);
  // An explicit mass scales the capsule's density.
  const double scale = link.mass > 0.0 ? link.mass / capsule.mass : 1.0;
  result.mass = capsule.mass * scale;
  const double axial = capsule.axial * scale;
  const double across = capsule.perpendicular * scale;
  result.inertia = AlongX(link) ? btVector3(axial, across, across)
                                : btVector3(across, across, axial);
  result.centre = btVector3((link.from_x + link.to_x) / 2.0, 0,
                            (link.from_z + link.to_z) / 2.0);
  return result;
}

absl::Status ValidateWorldSettings(const PlanarModel& model) {
  if (!(model.timestep > 0.0) || model.solver_iterations < 1 ||
      !(model.density > 0.0) || !(std::abs(model.slope) < kPi / 4)) {
    return absl::InvalidArgumentError(
        "planar model: timestep and density must be > 0, solver_iterations "
        ">= 1 and |slope| < 45 degrees");
  }
  if (!model.ground_heights.empty()) {
    if (model.ground_heights.size() < 2 || !(model.ground_spacing > 0.0)) {
      return absl::InvalidArgumentError(
          "planar model: a ground profile needs 2 or more heights and a "
          "spacing > 0");
    }
    for (double h : model.ground_heights) {
      if (!std::isfinite(h)) {
        return absl::InvalidArgumentError(
            "planar model: the ground profile has a non-finite height");
      }
    }
  }
  return absl::OkStatus();
}

absl::Status BadLink(size_t i, const PlanarLink& link, absl::string_view why) {
  return absl::InvalidArgumentError(
      absl::StrCat("planar model: link ", i, " (", link.name, ") ", why));
}

// The root has no hinge: only these checks apply to it.
absl::Status ValidateLinkBody(const PlanarModel& model, size_t i) {
  const PlanarLink& link = model.links[i];
  if (i == 0 ? link.parent != -1
             : link.parent < 0 || link.parent >= static_cast<int>(i)) {
    return BadLink(i, link, "needs the root's parent -1, else an earlier link");
  }
  if (!(link.mass >= 0.0) || !(link.friction >= 0.0)) {
    return BadLink(i, link, "needs mass >= 0 and friction >= 0");
  }
  if (link.is_box()) {
    if (!(link.box_depth > 0.0) || !(link.box_height > 0.0)) {
      return BadLink(i, link, "needs a box depth and height > 0");
    }
  } else {
    if (link.from_x != link.to_x && link.from_z != link.to_z) {
      return BadLink(i, link, "is not parallel to x or z");
    }
    if (!(link.radius > 0.0)) return BadLink(i, link, "needs radius > 0");
  }
  return absl::OkStatus();
}

absl::Status ValidateHinge(const PlanarModel& model, size_t i) {
  const PlanarLink& link = model.links[i];
  if (link.axis != 1.0 && link.axis != -1.0) {
    return BadLink(i, link, "needs axis +-1");
  }
  if (!(link.lower < link.upper) || !(link.damping >= 0.0) ||
      !(link.armature >= 0.0)) {
    return BadLink(i, link,
                   "needs lower < upper, damping >= 0 and armature >= 0");
  }
  // The damping torque is explicit: it must not overshoot within one
  // step, i.e. damping * dt well below the link's inertia about its hinge.
  const LinkInertia body = InertiaOf(link, model.density);
  const double cx = body.centre.x() - link.joint_x;
  const double cz = body.centre.z() - link.joint_z;
  const double about_hinge =
      body.inertia.y() + link.armature + body.mass * (cx * cx + cz * cz);
  if (link.damping * model.timestep > 0.5 * about_hinge) {
    return BadLink(
        i, link,
        absl::StrCat("damping ", link.damping,
                     " is too high for an explicit step of ", model.timestep,
                     " s (inertia ", about_hinge, ")"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidatePlanarModel(const PlanarModel& model) {
  if (model.links.empty()) {
    return absl::InvalidArgumentError("planar model: no links");
  }
  if (absl::Status status = ValidateWorldSettings(model); !status.ok()) {
    return status;
  }
  for (size_t i = 0; i < model.links.size(); ++i) {
    if (absl::Status status = ValidateLinkBody(model, i); !status.ok()) {
      return status;
    }
    if (i == 0) continue;
    if (absl::Status status = ValidateHinge(model, i); !status.ok()) {
      return status;
    }
  }
  return absl::OkStatus();
}

BulletWorld::BulletWorld(const PlanarModel& model)
    : slope_tangent_(std::tan(model.slope)),
      ground_heights_(model.ground_heights),
      ground_start_x_(model.ground_start_x),
      ground_spacing_(model.ground_spacing),
      timestep_(model.timestep) {
  const int links = static_cast<int>(model.links.size());
  num_dofs_ = 2 + links;
  int rotors = 0;
  for (int i = 1; i < links; ++i) {
    rotors_.push_back(
        model.links[i].armature > 0.0 ? LinkIndex(links) + rotors++ : -1);
  }
  CreateDynamicsWorld(model);
  CreateGround(model);
  CreateBody(model, rotors);
  AddColliders(model);
  AddJointConstraints(model);
  std::vector<double> q(num_dofs_, 0.0);
  const std::vector<double> qd(num_dofs_, 0.0);
  q[1] = model.root_z;
  SetState(q, qd);
}

void BulletWorld::CreateDynamicsWorld(const PlanarModel& model) {
  // Small pools: the defaults (4096 entries) cost a few megabytes per world,
  // and a world is built for every episode. Pools overflow to the heap.
  btDefaultCollisionConstructionInfo construction;
  construction.m_defaultMaxPersistentManifoldPoolSize = 64;
  construction.m_defaultMaxCollisionAlgorithmPoolSize = 64;
  collision_config_ =
      std::make_unique<btDefaultCollisionConfiguration>(construction);
  dispatcher_ =
      std::make_unique<btCollisionDispatcher>(collision_config_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btMultiBodyConstraintSolver>();
  world_ = std::make_unique<btMultiBodyDynamicsWorld>(
      dispatcher_.get(), broadphase_.get(), solver_.get(),
      collision_config_.get());
  world_->setGravity(btVector3(0, 0, -model.gravity));
  world_->getSolverInfo().m_numIterations = model.solver_iterations;
}

void BulletWorld::CreateGround(const PlanarModel& model) {
  if (ground_heights_.empty()) {
    const btVector3 normal(-std::sin(model.slope), 0, std::cos(model.slope));
    ground_shape_ = std::make_unique<btStaticPlaneShape>(normal, 0);
  } else {
    // The profile as a strip of triangles across y, wide enough for any
    // body of the plane, with a level run-out of kRunOut at both ends.
    ground_mesh_ = std::make_unique<btTriangleMesh>();
    const int n = static_cast<int>(ground_heights_.size());
    const auto x_at = [&](int i) {
      return ground_start_x_ + i * ground_spacing_;
    };
    const auto add = [&](double x0, double h0, double x1, double h1) {
      const btVector3 a(x0, -kGroundHalfWidth, h0),
          b(x1, -kGroundHalfWidth, h1);
      const btVector3 c(x1, kGroundHalfWidth, h1), d(x0, kGroundHalfWidth, h0);
      ground_mesh_->addTriangle(a, b, c);
      ground_mesh_->addTriangle(a, c, d);
    };
    add(x_at(0) - kRunOut, ground_heights_.front(), x_at(0),
        ground_heights_.front());
    for (int i = 0; i + 1 < n; ++i) {
      add(x_at(i), ground_heights_[i], x_at(i + 1), ground_heights_[i + 1]);
    }
    add(x_at(n - 1), ground_heights_.back(), x_at(n - 1) + kRunOut,
        ground_heights_.back());
    auto shape =
        std::make_unique<btBvhTriangleMeshShape>(ground_mesh_.get(), true);
    shape->setMargin(kBoxMargin);
    ground_shape_ = std::move(shape);
  }
  btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr,
                                                       ground_shape_.get());
  ground_info.m_friction = 1.0;
  ground_info.m_restitution = 0.0;
  ground_ = std::make_unique<btRigidBody>(ground_info);
  world_->addRigidBody(ground_.get(), kGroundGroup, kBodyGroup);
}

void BulletWorld::CreateBody(const PlanarModel& model, int rotors) {
  const int links = static_cast<int>(model.links.size());
  body_ = std::make_unique<btMultiBody>(LinkIndex(links) + rotors, 0.0,
                                        btVector3(0, 0, 0),
                                        /*fixedBase=*/true,
                                        /*canSleep=*/false);
  const btQuaternion identity = btQuaternion::getIdentity();
  const btVector3 zero(0, 0, 0);
  const btVector3 slide_inertia(kSlideInertia, kSlideInertia, kSlideInertia);
  body_->setupPrismatic(0, kSlideMass, slide_inertia, -1, identity,
                        btVector3(1, 0, 0), zero, zero, true);
  body_->setupPrismatic(1, kSlideMass, slide_inertia, 0, identity,
                        btVector3(0, 0, 1), zero, zero, true);
  std::vector<btVector3> centres;
  chains_.resize(links);
  for (int i = 0; i < links; ++i) {
    const PlanarLink& link = model.links[i];
    const LinkInertia body = InertiaOf(link, model.density);
    const btVector3 centre = body.centre;
    centres.push_back(centre);
    const btVector3 inertia = body.inertia;
    if (i == 0) {
      body_->setupRevolute(LinkIndex(0), body.mass, inertia, 1, identity,
                           btVector3(0, 1, 0), zero,
                           centre - btVector3(0, 0, model.root_z), true);
    } else {
      const btVector3 joint(link.joint_x, 0, link.joint_z);
      body_->setupRevolute(LinkIndex(i), body.mass, inertia,
                           LinkIndex(link.parent), identity,
                           btVector3(0, link.axis, 0),
                           joint - centres[link.parent], centre - joint, true);
      damping_.push_back(link.damping);
      axes_.push_back(link.axis);
      chains_[i] = chains_[link.parent];
      chains_[i].push_back(i - 1);
      if (rotors_[i - 1] >= 0) {
        // Spinning about its centre on the fixed base: only the gear
        // constraint moves it, and the base takes its reaction.
        body_->setupRevolute(
            rotors_[i - 1], kSlideMass,
            btVector3(link.armature, link.armature, link.armature), -1,
            identity, btVector3(0, link.axis, 0), zero, zero, true);
      }
    }
    shapes_.push_back(LinkShape(link));
  }
  body_->finalizeMultiDof();
  // MuJoCo's bodies have no drag; Bullet's default damps every link.
  body_->setLinearDamping(0.0);
  body_->setAngularDamping(0.0);
  body_->setHasSelfCollision(false);
  world_->addMultiBody(body_.get());
}

std::unique_ptr<btCollisionShape> BulletWorld::LinkShape(
    const PlanarLink& link) {
  if (link.is_box()) {
    auto box = std::make_unique<btBoxShape>(
        btVector3(link.box_width / 2, link.box_depth / 2, link.box_height / 2));
    // Bullet's default margin (4 cm) lies inside the box and exceeds a thin
    // one's half height (a 5 cm foot).
    box->setMargin(kBoxMargin);
    return box;
  }
  if (AlongX(link)) {
    return std::make_unique<btCapsuleShapeX>(link.radius, SegmentLength(link));
  }
  return std::make_unique<btCapsuleShapeZ>(link.radius, SegmentLength(link));
}

void BulletWorld::AddColliders(const PlanarModel& model) {
  for (size_t i = 0; i < model.links.size(); ++i) {
    const int link = static_cast<int>(i);
    auto collider =
        std::make_unique<btMultiBodyLinkCollider>(body_.get(), LinkIndex(link));
    collider->setCollisionShape(shapes_[i].get());
    collider->setFriction(model.links[i].friction);
    collider->setRestitution(0.0);
    world_->addCollisionObject(collider.get(), kBodyGroup, kGroundGroup);
    body_->getLink(LinkIndex(link)).m_collider = collider.get();
    colliders_.push_back(std::move(collider));
  }
}

void BulletWorld::AddJointConstraints(const PlanarModel& model) {
  const int links = static_cast<int>(model.links.size());
  for (int i = 1; i < links; ++i) {
    const PlanarLink& link = model.links[i];
    limits_.push_back(std::make_unique<btMultiBodyJointLimitConstraint>(
        body_.get(), LinkIndex(i), link.lower, link.upper));
    world_->addMultiBodyConstraint(limits_.back().get());
  }
  const btMatrix3x3 frame = btMatrix3x3::getIdentity();
  const btVector3 zero(0, 0, 0);
  for (int j = 0; j < links - 1; ++j) {
    if (rotors_[j] < 0) continue;
    // Rows: qdot(hinge) + ratio * qdot(rotor) = 0.
    gears_.push_back(std::make_unique<btMultiBodyGearConstraint>(
        body_.get(), LinkIndex(j + 1), body_.get(), rotors_[j], zero, zero,
        frame, frame));
    gears_.back()->setGearRatio(-1.0);
    world_->addMultiBodyConstraint(gears_.back().get());
  }
}

BulletWorld::~BulletWorld() {
  for (auto& gear : gears_) world_->removeMultiBodyConstraint(gear.get());
  for (auto& limit : limits_) world_->removeMultiBodyConstraint(limit.get());
  for (auto& collider : colliders_) {
    world_->removeCollisionObject(collider.get());
  }
  world_->removeMultiBody(body_.get());
  world_->removeRigidBody(ground_.get());
  world_.reset();
}

double BulletWorld::q(int i) const { return body_->getJointPos(DofLink(i)); }

double BulletWorld::qd(int i) const { return body_->getJointVel(DofLink(i)); }

void BulletWorld::SetState(absl::Span<const double> q,
                           absl::Span<const double> qd) {
  for (int i = 0; i < num_dofs_; ++i) {
    body_->setJointPos(DofLink(i), q[i]);
    body_->setJointVel(DofLink(i), qd[i]);
  }
  for (size_t j = 0; j < rotors_.size(); ++j) {
    if (rotors_[j] >= 0) body_->setJointVel(rotors_[j], qd[3 + j]);
  }
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  body_->forwardKinematics(world_to_local, local_origin);
  body_->updateCollisionObjectWorldTransforms(world_to_local, local_origin);
}

void BulletWorld::Step(absl::Span<const double> torques, int substeps) {
  const int hinges = num_dofs_ - 3;
  for (int s = 0; s < substeps; ++s) {
    body_->clearForcesAndTorques();
    for (int j = 0; j < hinges; ++j) {
      const int link = DofLink(3 + j);
      body_->addJointTorque(
          link, torques[j] - damping_[j] * body_->getJointVel(link));
    }
    // maxSubSteps 0: exactly one step of timestep_, no interpolation.
    world_->stepSimulation(timestep_, 0, timestep_);
  }
}

double BulletWorld::GroundHeight(double x) const {
  if (ground_heights_.empty()) return x * slope_tangent_;
  const double at = (x - ground_start_x_) / ground_spacing_;
  const int last = static_cast<int>(ground_heights_.size()) - 1;
  if (!(at > 0.0)) return ground_heights_.front();
  if (at >= last) return ground_heights_.back();
  const int i = static_cast<int>(at);
  const double blend = at - i;
  return ground_heights_[i] +
         blend * (ground_heights_[i + 1] - ground_heights_[i]);
}

double BulletWorld::LinkPitch(int link) const {
  double pitch = q(2);
  for (int hinge : chains_[link]) pitch += axes_[hinge] * q(3 + hinge);
  return pitch;
}

bool BulletWorld::TouchesGround(int link) const {
  const btCollisionObject* collider = colliders_[link].get();
  const int manifolds = dispatcher_->getNumManifolds();
  for (int m = 0; m < manifolds; ++m) {
    const btPersistentManifold* manifold =
        dispatcher_->getInternalManifoldPointer()[m];
    if (manifold->getBody0() != collider && manifold->getBody1() != collider) {
      continue;
    }
    for (int c = 0; c < manifold->getNumContacts(); ++c) {
      if (manifold->getContactPoint(c).getDistance() < kTouchDistance) {
        return true;
      }
    }
  }
  return false;
}

bool BulletWorld::IsFinite() const {
  for (int i = 0; i < num_dofs_; ++i) {
    if (!std::isfinite(q(i)) || !std::isfinite(qd(i))) return false;
  }
  return true;
}

double BulletWorld::LinkMass(int link) const {
  return body_->getLinkMass(LinkIndex(link));
}

CapsulePose BulletWorld::LinkCapsule(int link) const {
  const btMultiBodyLinkCollider* collider = colliders_[link].get();
  const btTransform& pose = collider->getWorldTransform();
  if (collider->getCollisionShape()->getShapeType() == BOX_SHAPE_PROXYTYPE) {
    const auto* box =
        static_cast<const btBoxShape*>(collider->getCollisionShape());
    const btVector3 extents = box->getHalfExtentsWithMargin();
    const bool wide = extents.x() >= extents.z();
    const double radius = wide ? extents.z() : extents.x();
    btVector3 half(0, 0, 0);
    half[wide ? 0 : 2] = (wide ? extents.x() : extents.z()) - radius;
    const btVector3 from = pose * -half;
    const btVector3 to = pose * half;
    return {from.x(), from.z(), to.x(), to.z(), radius};
  }
  const auto* shape =
      static_cast<const btCapsuleShape*>(collider->getCollisionShape());
  btVector3 half(0, 0, 0);
  half[shape->getUpAxis()] = shape->getHalfHeight();
  const btVector3 from = pose * -half;
  const btVector3 to = pose * half;
  CapsulePose capsule;
  capsule.from_x = from.x();
  capsule.from_z = from.z();
  capsule.to_x = to.x();
  capsule.to_z = to.z();
  capsule.radius = shape->getRadius();
  return capsule;
}

}  // namespace vantage
