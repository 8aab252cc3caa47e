#include "actor/envs/mujoco/mujoco_renderer.h"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/mujoco_model.h"

namespace vantage {
namespace {

// MuJoCo's scene holds at most this many geoms per frame.
constexpr int kMaxGeoms = 2000;
// Marks on the floor, one a metre, this many either side of the camera.
constexpr int kFloorMarks = 12;

// The built-in models carry no materials, lights or skybox (and changing
// them would change the models that checkpoints fingerprint), so the
// renderer's copy gets its colours here.
constexpr float kBodyColour[4] = {0.85f, 0.45f, 0.20f, 1.0f};
constexpr float kFloorColour[4] = {0.55f, 0.50f, 0.42f, 1.0f};
constexpr float kMarkColour[4] = {0.30f, 0.26f, 0.20f, 1.0f};
constexpr float kSkyTop[3] = {0.45f, 0.65f, 0.90f};
constexpr float kSkyHorizon[3] = {0.85f, 0.92f, 0.98f};

bool DefaultColour(const float* rgba) {
  return rgba[0] == 0.5f && rgba[1] == 0.5f && rgba[2] == 0.5f;
}

void Brighten(mjModel* m) {
  for (int i = 0; i < 3; ++i) {
    m->vis.headlight.ambient[i] = 0.35f;
    m->vis.headlight.diffuse[i] = 0.65f;
    m->vis.headlight.specular[i] = 0.15f;
  }
  for (int g = 0; g < m->ngeom; ++g) {
    float* rgba = m->geom_rgba + 4 * g;
    if (m->geom_matid[g] >= 0 || !DefaultColour(rgba)) continue;
    const float* colour =
        m->geom_type[g] == mjGEOM_PLANE ? kFloorColour : kBodyColour;
    std::copy(colour, colour + 4, rgba);
  }
}

// Half the size of the subtree under `body`: a tracking camera keeps it in
// the frame.
double SubtreeRadius(const mjModel* m, const mjData* d, int body) {
  const double* centre = d->subtree_com + 3 * body;
  double radius = 0.1;
  for (int g = 0; g < m->ngeom; ++g) {
    int b = m->geom_bodyid[g];
    while (b != 0 && b != body) b = m->body_parentid[b];
    if (b != body) continue;
    const double* at = d->geom_xpos + 3 * g;
    const double dx = at[0] - centre[0];
    const double dy = at[1] - centre[1];
    const double dz = at[2] - centre[2];
    radius = std::max(
        radius, std::sqrt(dx * dx + dy * dy + dz * dz) + m->geom_rbound[g]);
  }
  return radius;
}

// Thin stripes across the floor (z = 0) every metre around `x`, so that
// motion shows while the camera follows the body.
void AddFloorMarks(mjvScene* scene, double x) {
  const double first = std::floor(x) - kFloorMarks;
  for (int k = 0; k <= 2 * kFloorMarks && scene->ngeom < scene->maxgeom; ++k) {
    mjvGeom* geom = scene->geoms + scene->ngeom++;
    const mjtNum size[3] = {0.02, 1.5, 0.001};
    const mjtNum pos[3] = {first + k, 0.0, 0.001};
    mjv_initGeom(geom, mjGEOM_BOX, size, pos, nullptr, kMarkColour);
    geom->category = mjCAT_DECOR;
  }
}

// Where nothing was drawn (depth at the far plane), a sky that fades to
// the horizon.
void PaintSky(const float* depth, int width, int height, uint8_t* rgb) {
  for (int y = 0; y < height; ++y) {
    // Row 0 is the bottom one.
    const float up = static_cast<float>(y) / std::max(1, height - 1);
    uint8_t sky[3];
    for (int c = 0; c < 3; ++c) {
      sky[c] = static_cast<uint8_t>(
          255.0f * (kSkyHorizon[c] + (kSkyTop[c] - kSkyHorizon[c]) * up));
    }
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (depth[i] < 1.0f) continue;
      std::copy(sky, sky + 3, rgb + 3 * i);
    }
  }
}

// libOSMesa (and the LLVM it pulls in: ~50 MB of a process's memory and
// ~50 ms of its start) is loaded at the first frame instead of linked, so
// the actors and learners, which never render, do not carry it. RTLD_GLOBAL
// puts its symbols in the process's global scope, where MuJoCo's GL loader
// looks for OSMesaGetCurrentContext (docs/videos.md).
struct OsmesaApi {
  decltype(&OSMesaCreateContextExt) create_context = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
};

absl::StatusOr<const OsmesaApi*> LoadOsmesa() {
  static const absl::StatusOr<OsmesaApi>* const api =
      new absl::StatusOr<OsmesaApi>([]() -> absl::StatusOr<OsmesaApi> {
        void* library = nullptr;
        for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"}) {
          library = dlopen(name, RTLD_NOW | RTLD_GLOBAL);
          if (library != nullptr) break;
        }
        if (library == nullptr) {
          return absl::FailedPreconditionError(absl::StrCat(
              "MuJoCo renderer: cannot load libOSMesa (", dlerror(),
              "; deploy/setup.sh installs libosmesa6-dev)"));
        }
        OsmesaApi loaded;
        loaded.create_context =
            reinterpret_cast<decltype(&OSMesaCreateContextExt)>(
                dlsym(library, "OSMesaCreateContextExt"));
        loaded.make_current = reinterpret_cast<decltype(&OSMesaMakeCurrent)>(
            dlsym(library, "OSMesaMakeCurrent"));
        loaded.destroy_context =
            reinterpret_cast<decltype(&OSMesaDestroyContext)>(
                dlsym(library, "OSMesaDestroyContext"));
        if (loaded.create_context == nullptr ||
            loaded.make_current == nullptr ||
            loaded.destroy_context == nullptr) {
          return absl::FailedPreconditionError(
              "MuJoCo renderer: libOSMesa lacks OSMesaCreateContextExt, "
              "OSMesaMakeCurrent or OSMesaDestroyContext");
        }
        return loaded;
      }());
  if (!api->ok()) return api->status();
  return &**api;
}

struct OsmesaDeleter {
  void operator()(osmesa_context* context) const {
    // A context exists only once the library is loaded.
    (*LoadOsmesa())->destroy_context(context);
  }
};
using OsmesaPtr = std::unique_ptr<osmesa_context, OsmesaDeleter>;

struct SceneDeleter {
  void operator()(mjvScene* scene) const {
    mjv_freeScene(scene);
    delete scene;
  }
};
struct ContextDeleter {
  void operator()(mjrContext* context) const {
    mjr_freeContext(context);
    delete context;
  }
};

}  // namespace

// Declared in this order so that they die in the reverse one: MuJoCo's GL
// objects while their context still exists, the context last.
struct MujocoRenderer::Gl {
  // OSMesa's default framebuffer; MuJoCo draws into its own offscreen one,
  // but a context needs a buffer to be current.
  std::vector<unsigned char> window;
  OsmesaPtr context;
  MjModelPtr model;
  MjDataPtr data;
  std::unique_ptr<mjvScene, SceneDeleter> scene;
  std::unique_ptr<mjrContext, ContextDeleter> gl_context;
  mjvOption option;
  std::vector<uint8_t> bottom_up;
  std::vector<float> depth;
  // Of the tracking camera, set at the first frame.
  double distance = 0.0;

  bool MakeCurrent(int width, int height) {
    return (*LoadOsmesa())
        ->make_current(context.get(), window.data(), GL_UNSIGNED_BYTE, width,
                       height);
  }
};

absl::StatusOr<std::unique_ptr<MujocoRenderer>> MujocoRenderer::Create(
    const mjModel* model, int width, int height) {
  if (width < 1 || height < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "MuJoCo renderer: a frame of ", width, "x", height, " pixels"));
  }
  absl::StatusOr<const OsmesaApi*> osmesa = LoadOsmesa();
  if (!osmesa.ok()) return osmesa.status();
  auto gl = std::make_unique<Gl>();
  gl->window.resize(static_cast<size_t>(width) * height * 4);
  // RGBA with a 24-bit depth and 8-bit stencil buffer, as mjr needs.
  gl->context.reset((*osmesa)->create_context(OSMESA_RGBA, 24, 8, 0, nullptr));
  if (gl->context == nullptr) {
    return absl::InternalError(
        "MuJoCo renderer: OSMesa cannot create a context");
  }
  if (!gl->MakeCurrent(width, height)) {
    return absl::InternalError(
        "MuJoCo renderer: OSMesa cannot make its context current");
  }
  absl::Status status = GuardMujoco([&] {
    gl->model.reset(mj_copyModel(nullptr, model));
    gl->data.reset(mj_makeData(gl->model.get()));
  });
  if (!status.ok()) return status;
  if (gl->model == nullptr || gl->data == nullptr) {
    return absl::ResourceExhaustedError(
        "MuJoCo renderer: cannot copy the model and data");
  }
  // mjr_makeContext sizes the offscreen framebuffer from these.
  Brighten(gl->model.get());
  mjVisual& visual = gl->model->vis;
  visual.global.offwidth = std::max(visual.global.offwidth, width);
  visual.global.offheight = std::max(visual.global.offheight, height);
  gl->scene.reset(new mjvScene);
  gl->gl_context.reset(new mjrContext);
  mjv_defaultScene(gl->scene.get());
  mjr_defaultContext(gl->gl_context.get());
  mjv_defaultOption(&gl->option);
  status = GuardMujoco([&] {
    mjv_makeScene(gl->model.get(), gl->scene.get(), kMaxGeoms);
    // MuJoCo's GL loader finds OSMesaGetProcAddress here, because an OSMesa
    // context is current (see docs/videos.md).
    mjr_makeContext(gl->model.get(), gl->gl_context.get(), mjFONTSCALE_150);
    mjr_setBuffer(mjFB_OFFSCREEN, gl->gl_context.get());
  });
  if (!status.ok()) return status;
  const mjrContext& context = *gl->gl_context;
  if (context.currentBuffer != mjFB_OFFSCREEN || context.offWidth < width ||
      context.offHeight < height) {
    return absl::InternalError(absl::StrCat(
        "MuJoCo renderer: no offscreen framebuffer of ", width, "x", height,
        " (got ", context.offWidth, "x", context.offHeight, ")"));
  }
  gl->bottom_up.resize(static_cast<size_t>(width) * height * 3);
  gl->depth.resize(static_cast<size_t>(width) * height);
  return std::unique_ptr<MujocoRenderer>(
      new MujocoRenderer(width, height, std::move(gl)));
}

MujocoRenderer::MujocoRenderer(int width, int height, std::unique_ptr<Gl> gl)
    : width_(width), height_(height), gl_(std::move(gl)) {}

MujocoRenderer::~MujocoRenderer() {
  // mjr_freeContext deletes GL objects: their context must be current.
  if (gl_ != nullptr) gl_->MakeCurrent(width_, height_);
}

absl::StatusOr<Frame> MujocoRenderer::Render(const mjData* data,
                                             const MujocoView& view) {
  // Another renderer's context may be current on this thread.
  if (!gl_->MakeCurrent(width_, height_)) {
    return absl::InternalError(
        "MuJoCo renderer: OSMesa cannot make its context current");
  }
  const mjModel* m = gl_->model.get();
  const bool tracking = view.track_body > 0 && view.track_body < m->nbody;
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  if (tracking) {
    // Side-on (looking along +y, so +x runs to the right), slightly above.
    if (gl_->distance == 0.0) {
      gl_->distance =
          std::clamp(4.5 * SubtreeRadius(m, data, view.track_body), 1.5, 12.0);
    }
    camera.type = mjCAMERA_TRACKING;
    camera.trackbodyid = view.track_body;
    camera.distance = gl_->distance;
    camera.azimuth = 90.0;
    camera.elevation = -15.0;
  } else if (m->ncam > 0) {
    camera.type = mjCAMERA_FIXED;
    camera.fixedcamid = 0;
  } else {
    camera.type = mjCAMERA_FREE;
    for (int i = 0; i < 3; ++i) camera.lookat[i] = m->stat.center[i];
    camera.distance = 1.2 * m->stat.extent;
    camera.azimuth = 90.0;
    camera.elevation = -35.0;
  }
  Frame frame;
  frame.width = width_;
  frame.height = height_;
  frame.rgb.resize(gl_->bottom_up.size());
  const mjrRect viewport = {0, 0, width_, height_};
  absl::Status status = GuardMujoco([&] {
    // The scene is built from a copy: mjv_updateScene takes non-const data.
    mj_copyData(gl_->data.get(), m, data);
    mjv_updateScene(m, gl_->data.get(), &gl_->option, nullptr, &camera,
                    mjCAT_ALL, gl_->scene.get());
    if (tracking) {
      AddFloorMarks(gl_->scene.get(), data->xpos[3 * view.track_body]);
    }
    mjr_setBuffer(mjFB_OFFSCREEN, gl_->gl_context.get());
    mjr_render(viewport, gl_->scene.get(), gl_->gl_context.get());
    mjr_readPixels(gl_->bottom_up.data(), gl_->depth.data(), viewport,
                   gl_->gl_context.get());
  });
  if (!status.ok()) return status;
  PaintSky(gl_->depth.data(), width_, height_, gl_->bottom_up.data());
  // OpenGL's rows run bottom-up.
  const size_t row = static_cast<size_t>(width_) * 3;
  for (int y = 0; y < height_; ++y) {
    std::memcpy(frame.rgb.data() + y * row,
                gl_->bottom_up.data() + (height_ - 1 - y) * row, row);
  }
  return frame;
}

}  // namespace vantage
