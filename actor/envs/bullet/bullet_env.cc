#include "actor/envs/bullet/bullet_env.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "actor/render/planar_drawing.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "bullet_env";
constexpr uint32_t kStateVersion = 1;

bool BitEqual(absl::Span<const double> a, absl::Span<const double> b) {
  return a.size() == b.size() &&
         (a.empty() ||
          std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// The state's fields are runs of doubles; their lengths decide how many.
bool ReadDoubles(absl::string_view bytes, std::vector<double>* out) {
  if (bytes.size() % sizeof(double) != 0) return false;
  out->resize(bytes.size() / sizeof(double));
  if (!out->empty()) std::memcpy(out->data(), bytes.data(), bytes.size());
  return true;
}

}  // namespace

BulletEnv::BulletEnv(EnvSpec spec, PlanarModel model, std::vector<double> gears,
                     int frame_skip)
    : spec_(std::move(spec)),
      model_(std::move(model)),
      gears_(std::move(gears)),
      frame_skip_(frame_skip) {
  spec_.discrete = false;
  spec_.action_size = static_cast<int64_t>(gears_.size());
  spec_.action_low.assign(gears_.size(), -1.0);
  spec_.action_high.assign(gears_.size(), 1.0);
  spec_.control_dt = model_.timestep * frame_skip_;
  clipped_.resize(gears_.size());
  torques_.resize(gears_.size());
}

void BulletEnv::Torques(const BulletWorld&, absl::Span<const double> clipped,
                        std::vector<double>& torques) const {
  for (size_t j = 0; j < gears_.size(); ++j) {
    torques[j] = gears_[j] * clipped[j];
  }
}

void BulletEnv::SetActionBounds(std::vector<double> low,
                                std::vector<double> high) {
  spec_.action_low = std::move(low);
  spec_.action_high = std::move(high);
}

std::vector<double> BulletEnv::ZeroPose() const {
  std::vector<double> q(model_.links.size() + 2, 0.0);
  q[1] = model_.root_z;
  return q;
}

void BulletEnv::Begin(uint64_t seed) {
  std::mt19937_64 rng(seed);
  PlanarModel model = model_;
  ShapeGround(rng, model);
  world_ = std::make_unique<BulletWorld>(model);
  std::vector<double> q = ZeroPose();
  std::vector<double> qd(q.size(), 0.0);
  ResetState(rng, q, qd);
  world_->SetState(q, qd);
  BeginEpisode(*world_);
  seed_ = seed;
  log_.clear();
  needs_reset_ = false;
}

absl::Status BulletEnv::Reset(uint64_t seed, absl::Span<double> observation) {
  if (absl::Status status = CheckObservationBuffer(spec_, observation);
      !status.ok()) {
    return status;
  }
  Begin(seed);
  Observe(*world_, observation.data());
  return absl::OkStatus();
}

absl::Status BulletEnv::Advance(absl::Span<const double> clipped,
                                StepResult* result) {
  BeforeStep(*world_);
  const int substeps = std::max(1, TorqueSubsteps());
  for (int done = 0; done < frame_skip_; done += substeps) {
    Torques(*world_, clipped, torques_);
    world_->Step(torques_, std::min(substeps, frame_skip_ - done));
  }
  if (!world_->IsFinite()) {
    return absl::InternalError(absl::StrCat(
        spec_.name,
        ": the simulation became unstable (non-finite positions "
        "or velocities) after ",
        log_.size() / gears_.size() + 1, " steps; reset the environment"));
  }
  *result = Evaluate(*world_, clipped);
  return absl::OkStatus();
}

absl::StatusOr<StepResult> BulletEnv::Step(absl::Span<const double> action,
                                           absl::Span<double> observation) {
  if (absl::Status status = CheckStep(spec_, needs_reset_, action, observation);
      !status.ok()) {
    return status;
  }
  for (size_t j = 0; j < clipped_.size(); ++j) {
    clipped_[j] =
        std::clamp(action[j], spec_.action_low[j], spec_.action_high[j]);
  }
  StepResult result;
  if (absl::Status status = Advance(clipped_, &result); !status.ok()) {
    needs_reset_ = true;
    return status;
  }
  log_.insert(log_.end(), clipped_.begin(), clipped_.end());
  Observe(*world_, observation.data());
  return result;
}

absl::Status BulletEnv::Replay(uint64_t seed, absl::Span<const double> log) {
  Begin(seed);
  const size_t width = gears_.size();
  StepResult result;
  for (size_t row = 0; row < log.size(); row += width) {
    absl::Span<const double> clipped = log.subspan(row, width);
    if (absl::Status status = Advance(clipped, &result); !status.ok()) {
      needs_reset_ = true;
      return status;
    }
    log_.insert(log_.end(), clipped.begin(), clipped.end());
  }
  return absl::OkStatus();
}

absl::StatusOr<Frame> BulletEnv::Render(int width, int height) {
  if (world_ == nullptr || needs_reset_) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec_.name, ": nothing to render before a Reset"));
  }
  PlanarScene scene;
  // The whole standing body fits in the frame, with room to jump.
  double top = 0.0;
  for (int i = 0; i < world_->num_links(); ++i) {
    const CapsulePose pose = world_->LinkCapsule(i);
    PlanarCapsule capsule;
    capsule.from_x = pose.from_x;
    capsule.from_z = pose.from_z;
    capsule.to_x = pose.to_x;
    capsule.to_z = pose.to_z;
    capsule.radius = pose.radius;
    capsule.far_side = absl::StartsWith(model_.links[i].name, "left");
    scene.capsules.push_back(capsule);
    const PlanarLink& link = model_.links[i];
    top = std::max(top, link.is_box()
                            ? link.box_centre_z + link.box_height / 2
                            : std::max(link.from_z, link.to_z) + link.radius);
  }
  scene.view_height = 1.8 * top;
  const PlanarCapsule& root = scene.capsules[0];
  scene.centre_x = 0.5 * (root.from_x + root.to_x);
  // The ground as the world has it, a point every 5 cm across the frame
  // (generously: the frame's width depends on its aspect).
  for (double x = scene.centre_x - 2.0 * scene.view_height;
       x <= scene.centre_x + 2.0 * scene.view_height; x += 0.05) {
    scene.ground.push_back({x, world_->GroundHeight(x)});
  }
  // The ground stays at the same height in the frame (a tenth above its
  // bottom edge) however the body bobs.
  scene.centre_z =
      world_->GroundHeight(scene.centre_x) + 0.4 * scene.view_height;
  return DrawPlanarScene(scene, width, height);
}

uint64_t BulletEnv::Signature() const {
  StateWriter writer("bullet_env_signature", 1);
  writer.PutI64(frame_skip_);
  writer.PutDoubles(gears_);
  writer.PutDoubles({model_.root_z, model_.density, model_.slope,
                     model_.gravity, model_.timestep});
  writer.PutI64(model_.solver_iterations);
  for (const PlanarLink& link : model_.links) {
    writer.PutBytes(link.name);
    writer.PutI64(link.parent);
    writer.PutDoubles({link.from_x, link.from_z, link.to_x, link.to_z,
                       link.radius, link.friction, link.joint_x, link.joint_z,
                       link.axis, link.lower, link.upper, link.damping,
                       link.armature});
  }
  writer.PutBytes(TaskSignature());
  return Fingerprint(std::move(writer).Finish());
}

absl::StatusOr<std::string> BulletEnv::SaveState() const {
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(spec_.name);
  writer.PutU64(Signature());
  writer.PutBool(needs_reset_);
  writer.PutU64(seed_);
  writer.PutDoubles(log_);
  std::vector<double> q, qd;
  if (!needs_reset_) {
    for (int i = 0; i < world_->num_dofs(); ++i) {
      q.push_back(world_->q(i));
      qd.push_back(world_->qd(i));
    }
  }
  writer.PutDoubles(q);
  writer.PutDoubles(qd);
  return std::move(writer).Finish();
}

// A state read and checked, not yet applied.
struct BulletEnv::SavedState {
  bool needs_reset = false;
  uint64_t seed = 0;
  std::vector<double> log;
  std::vector<double> q;
  std::vector<double> qd;
};

absl::Status BulletEnv::RestoreState(absl::string_view state) {
  const std::string context = absl::StrCat(spec_.name, ": Bullet state");
  absl::StatusOr<SavedState> saved = ReadState(state, context);
  if (!saved.ok()) return saved.status();
  if (saved->needs_reset) {
    world_.reset();
    log_.clear();
    needs_reset_ = true;
    return absl::OkStatus();
  }
  return ReplayState(*saved, context);
}

absl::StatusOr<BulletEnv::SavedState> BulletEnv::ReadState(
    absl::string_view state, const std::string& context) const {
  StateReader reader(state, kStateKind, kStateVersion, context);
  reader.ExpectEqual("the environment", reader.GetBytes("name"), spec_.name);
  reader.Check(reader.GetU64("signature") == Signature(),
               "the state was saved by a task with another model or rules");
  SavedState saved;
  saved.needs_reset = reader.GetBool("needs_reset");
  saved.seed = reader.GetU64("seed");
  const absl::string_view log_bytes = reader.GetBytes("action log");
  const absl::string_view q_bytes = reader.GetBytes("positions");
  const absl::string_view qd_bytes = reader.GetBytes("velocities");
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  const size_t width = gears_.size();
  const size_t dofs = model_.links.size() + 2;
  bool ok = ReadDoubles(log_bytes, &saved.log) &&
            ReadDoubles(q_bytes, &saved.q) &&
            ReadDoubles(qd_bytes, &saved.qd) && saved.log.size() % width == 0;
  ok = ok && (saved.needs_reset
                  ? saved.log.empty() && saved.q.empty() && saved.qd.empty()
                  : saved.q.size() == dofs && saved.qd.size() == dofs);
  if (!ok) {
    return absl::InvalidArgumentError(absl::StrCat(
        context,
        ": the action log, positions or velocities have impossible "
        "sizes"));
  }
  if (absl::Status status = CheckActionLog(saved.log, context); !status.ok()) {
    return status;
  }
  return saved;
}

absl::Status BulletEnv::CheckActionLog(const std::vector<double>& log,
                                       const std::string& context) const {
  const size_t width = gears_.size();
  for (size_t i = 0; i < log.size(); ++i) {
    const size_t j = i % width;
    if (!(log[i] >= spec_.action_low[j] && log[i] <= spec_.action_high[j])) {
      return absl::InvalidArgumentError(
          absl::StrCat(context, ": logged action ", i / width, " entry ", j,
                       " (", log[i], ") is not a clipped action"));
    }
  }
  return absl::OkStatus();
}

absl::Status BulletEnv::ReplayState(const SavedState& saved,
                                    const std::string& context) {
  // Replaying changes the environment; if the result is not the saved one,
  // go back by replaying this environment's own state.
  absl::StatusOr<std::string> before = SaveState();
  if (!before.ok()) return before.status();
  absl::Status status = Replay(saved.seed, saved.log);
  if (status.ok()) {
    std::vector<double> replayed_q, replayed_qd;
    for (int i = 0; i < world_->num_dofs(); ++i) {
      replayed_q.push_back(world_->q(i));
      replayed_qd.push_back(world_->qd(i));
    }
    if (BitEqual(replayed_q, saved.q) && BitEqual(replayed_qd, saved.qd)) {
      return absl::OkStatus();
    }
    status = absl::InvalidArgumentError(
        absl::StrCat(context,
                     ": replaying the logged actions does not reproduce the "
                     "saved positions and velocities (a state from another "
                     "Bullet build, or a corrupted one)"));
  } else {
    status = absl::InvalidArgumentError(absl::StrCat(
        context, ": replaying the logged actions failed: ", status.message()));
  }
  if (absl::Status back = RestoreState(*before); !back.ok()) {
    needs_reset_ = true;
  }
  return status;
}

}  // namespace vantage
