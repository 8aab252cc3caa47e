#include "actor/envs/mujoco/mujoco_env.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/mujoco_renderer.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "mujoco_env";
constexpr uint32_t kStateVersion = 1;

struct NamedSize {
  const char* name;
  int64_t value;
};

// What the buffer's layout depends on; a blob from a model that differs in
// any of them (another task, another MJCF file under the same path) is
// refused.
std::array<NamedSize, 12> LayoutSizes(const mjModel* m, const mjData* d) {
  return {{{"MuJoCo version", mj_version()},
           {"nq", m->nq},
           {"nv", m->nv},
           {"na", m->na},
           {"nu", m->nu},
           {"nbody", m->nbody},
           {"nmocap", m->nmocap},
           {"nuserdata", m->nuserdata},
           {"nsensordata", m->nsensordata},
           {"nconmax", m->nconmax},
           {"njmax", m->njmax},
           {"nbuffer", d->nbuffer}}};
}

}  // namespace

MujocoEnv::MujocoEnv(EnvSpec spec, MjModelPtr model, MjDataPtr data,
                     int frame_skip)
    : spec_(std::move(spec)),
      model_(std::move(model)),
      data_(std::move(data)),
      frame_skip_(frame_skip) {
  const mjModel* m = model_.get();
  spec_.discrete = false;
  spec_.action_size = m->nu;
  spec_.action_low.assign(m->nu, -std::numeric_limits<double>::infinity());
  spec_.action_high.assign(m->nu, std::numeric_limits<double>::infinity());
  for (int i = 0; i < m->nu; ++i) {
    if (m->actuator_ctrllimited[i]) {
      spec_.action_low[i] = m->actuator_ctrlrange[2 * i];
      spec_.action_high[i] = m->actuator_ctrlrange[2 * i + 1];
    }
  }
  spec_.control_dt = m->opt.timestep * frame_skip_;
  clipped_.resize(m->nu);
  std::string mjb(mj_sizeModel(m), '\0');
  mj_saveModel(m, nullptr, mjb.data(), static_cast<int>(mjb.size()));
  model_fingerprint_ = Fingerprint(mjb);
}

MujocoEnv::~MujocoEnv() = default;

absl::StatusOr<Frame> MujocoEnv::Render(int width, int height) {
  if (needs_reset_) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec_.name, ": nothing to render before a Reset"));
  }
  if (renderer_ == nullptr || renderer_->width() != width ||
      renderer_->height() != height) {
    renderer_.reset();
    absl::StatusOr<std::unique_ptr<MujocoRenderer>> made =
        MujocoRenderer::Create(model_.get(), width, height);
    if (!made.ok()) return made.status();
    renderer_ = *std::move(made);
  }
  MujocoView view;
  view.track_body = TrackedBody();
  return renderer_->Render(data_.get(), view);
}

absl::Status MujocoEnv::Reset(uint64_t seed, absl::Span<double> observation) {
  if (absl::Status status = CheckObservationBuffer(spec_, observation);
      !status.ok()) {
    return status;
  }
  rng_.seed(seed);
  absl::Status status = GuardMujoco([&] {
    mj_resetData(model_.get(), data_.get());
    ResetState(rng_);
    mj_forward(model_.get(), data_.get());
  });
  if (!status.ok()) return status;
  Observe(observation.data());
  needs_reset_ = false;
  return absl::OkStatus();
}

absl::StatusOr<StepResult> MujocoEnv::Step(absl::Span<const double> action,
                                           absl::Span<double> observation) {
  if (absl::Status status = CheckStep(spec_, needs_reset_, action, observation);
      !status.ok()) {
    return status;
  }
  mjData* d = data_.get();
  for (int i = 0; i < model_->nu; ++i) {
    clipped_[i] =
        std::clamp(action[i], spec_.action_low[i], spec_.action_high[i]);
    d->ctrl[i] = clipped_[i];
  }
  BeforeStep();
  for (int w : {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC}) {
    d->warning[w].number = 0;
  }
  absl::Status status = GuardMujoco([&] {
    for (int i = 0; i < frame_skip_; ++i) mj_step(model_.get(), d);
    // mj_step leaves body and site positions at the start of its last
    // substep; rewards and observations read them at the end.
    mj_kinematics(model_.get(), d);
  });
  if (status.ok()) {
    for (const auto& [warning, what] :
         {std::make_pair(mjWARN_BADQPOS, "qpos"),
          std::make_pair(mjWARN_BADQVEL, "qvel"),
          std::make_pair(mjWARN_BADQACC, "qacc")}) {
      if (d->warning[warning].number > 0) {
        status = absl::InternalError(
            absl::StrCat(spec_.name, ": the simulation became unstable (bad ",
                         what, ") at t=", d->time, "s; reset the environment"));
        break;
      }
    }
  }
  if (!status.ok()) {
    needs_reset_ = true;
    return status;
  }
  const StepResult result = Evaluate(clipped_);
  Observe(observation.data());
  return result;
}

absl::StatusOr<std::string> MujocoEnv::SaveState() const {
  const mjData* d = data_.get();
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(spec_.name);
  for (const NamedSize& size : LayoutSizes(model_.get(), d)) {
    writer.PutI64(size.value);
  }
  writer.PutU64(model_fingerprint_);
  writer.PutDouble(d->time);
  writer.PutDoubles(d->energy);
  writer.PutI64s({d->ne, d->nf, d->nefc, d->ncon});
  writer.PutI64s({d->solver_iter, d->solver_nnz});
  writer.PutDoubles(d->solver_fwdinv);
  // Step reads the warning counters; the timers and per-iteration solver
  // statistics are diagnostics that the next step overwrites.
  std::vector<int64_t> warnings;
  for (const mjWarningStat& warning : d->warning) {
    warnings.push_back(warning.lastinfo);
    warnings.push_back(warning.number);
  }
  writer.PutI64s(warnings);
  writer.PutPacked(absl::string_view(static_cast<const char*>(d->buffer),
                                     static_cast<size_t>(d->nbuffer)));
  writer.PutEngine(rng_);
  writer.PutBool(needs_reset_);
  writer.PutBytes(SaveTaskState());
  return std::move(writer).Finish();
}

// A state read and checked, not yet applied.
struct MujocoEnv::SavedState {
  double time = 0.0;
  std::vector<double> energy;
  // ne, nf, nefc, ncon.
  std::vector<int64_t> counts;
  // solver_iter, solver_nnz.
  std::vector<int64_t> solver;
  std::vector<double> fwdinv;
  // lastinfo and number of each warning.
  std::vector<int64_t> warnings;
  std::string buffer;
  std::mt19937_64 rng;
  bool needs_reset = false;
  absl::string_view task;
};

absl::Status MujocoEnv::RestoreState(absl::string_view state) {
  absl::StatusOr<SavedState> saved = ReadState(state);
  if (!saved.ok()) return saved.status();
  if (absl::Status status = RestoreTaskState(saved->task); !status.ok()) {
    return status;
  }
  ApplyState(*saved);
  return absl::OkStatus();
}

absl::StatusOr<MujocoEnv::SavedState> MujocoEnv::ReadState(
    absl::string_view state) const {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  StateReader reader(state, kStateKind, kStateVersion,
                     absl::StrCat(spec_.name, ": MuJoCo state"));
  reader.ExpectEqual("the environment", reader.GetBytes("name"), spec_.name);
  for (const NamedSize& size : LayoutSizes(m, d)) {
    reader.ExpectEqual(size.name, reader.GetI64(size.name), size.value);
  }
  const uint64_t fingerprint = reader.GetU64("model fingerprint");
  reader.Check(fingerprint == model_fingerprint_,
               "the state was saved with another MuJoCo model (the "
               "fingerprints differ)");
  SavedState saved;
  saved.time = reader.GetDouble("time");
  saved.energy = reader.GetDoubles("energy", 2);
  saved.counts = reader.GetI64s("constraint counts", 4);
  saved.solver = reader.GetI64s("solver counts", 2);
  saved.fwdinv = reader.GetDoubles("solver_fwdinv", 2);
  saved.warnings = reader.GetI64s("warnings", 2 * mjNWARNING);
  saved.buffer = reader.GetPacked("buffer", static_cast<size_t>(d->nbuffer));
  saved.rng = reader.GetEngine("reset generator");
  saved.needs_reset = reader.GetBool("needs_reset");
  saved.task = reader.GetBytes("task state");
  reader.Check(std::isfinite(saved.time), "time is not finite");
  CheckCounts(saved, reader);
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  return saved;
}

void MujocoEnv::CheckCounts(const SavedState& saved,
                            StateReader& reader) const {
  const mjModel* m = model_.get();
  const int64_t ne = saved.counts[0];
  const int64_t nf = saved.counts[1];
  const int64_t nefc = saved.counts[2];
  const int64_t ncon = saved.counts[3];
  reader.Check(ne >= 0 && nf >= 0 && ne + nf <= nefc && nefc <= m->njmax &&
                   ncon >= 0 && ncon <= m->nconmax,
               absl::StrCat("impossible constraint counts ne=", ne, " nf=", nf,
                            " nefc=", nefc, " ncon=", ncon));
  reader.Check(saved.solver[0] >= 0 && saved.solver[0] <= mjNSOLVER &&
                   saved.solver[1] >= 0 &&
                   saved.solver[1] <= std::numeric_limits<int>::max(),
               "impossible solver counts");
  bool warnings_fit = true;
  for (int64_t value : saved.warnings) {
    warnings_fit &= value >= std::numeric_limits<int>::min() &&
                    value <= std::numeric_limits<int>::max();
  }
  reader.Check(warnings_fit, "warning counters out of range");
}

void MujocoEnv::ApplyState(const SavedState& saved) {
  mjData* d = data_.get();
  d->time = saved.time;
  std::copy(saved.energy.begin(), saved.energy.end(), d->energy);
  d->ne = static_cast<int>(saved.counts[0]);
  d->nf = static_cast<int>(saved.counts[1]);
  d->nefc = static_cast<int>(saved.counts[2]);
  d->ncon = static_cast<int>(saved.counts[3]);
  d->solver_iter = static_cast<int>(saved.solver[0]);
  d->solver_nnz = static_cast<int>(saved.solver[1]);
  std::copy(saved.fwdinv.begin(), saved.fwdinv.end(), d->solver_fwdinv);
  for (int i = 0; i < mjNWARNING; ++i) {
    d->warning[i].lastinfo = static_cast<int>(saved.warnings[2 * i]);
    d->warning[i].number = static_cast<int>(saved.warnings[2 * i + 1]);
  }
  std::memcpy(d->buffer, saved.buffer.data(), saved.buffer.size());
  rng_ = saved.rng;
  needs_reset_ = saved.needs_reset;
}

absl::Status MujocoEnv::RestoreTaskState(absl::string_view state) {
  if (state.empty()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(spec_.name, ": MuJoCo state: carries ", state.size(),
                   " bytes of task state, but this task keeps none"));
}

void MujocoEnv::PerturbState(std::mt19937_64& rng, double scale,
                             bool normal_qvel) {
  mjData* d = data_.get();
  std::uniform_real_distribution<double> uniform(-scale, scale);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < model_->nq; ++i) d->qpos[i] += uniform(rng);
  for (int i = 0; i < model_->nv; ++i) {
    d->qvel[i] += normal_qvel ? scale * normal(rng) : uniform(rng);
  }
}

}  // namespace vantage
