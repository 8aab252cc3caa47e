#include "common/nn/network_config.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

const std::vector<ConvTorsoDesign>& Designs() {
  static const auto* designs = new std::vector<ConvTorsoDesign>{
      {Torso::kMinAtar, "minatar", {{16, 3, 1}}, 128},
      {Torso::kNature, "nature", {{32, 8, 4}, {64, 4, 2}, {64, 3, 1}}, 512},
      {Torso::kEx2Doom, "ex2doom", {{16, 4, 4}, {16, 4, 4}}, 32},
  };
  return *designs;
}

// The smallest side the design takes.
int64_t SmallestSide(const ConvTorsoDesign& design) {
  int64_t side = 1;
  while (ConvOutputSide(design, side) < 1) ++side;
  return side;
}

}  // namespace

const ConvTorsoDesign* FindConvTorsoDesign(Torso torso) {
  for (const ConvTorsoDesign& design : Designs()) {
    if (design.torso == torso) return &design;
  }
  return nullptr;
}

int64_t ConvOutputSide(const ConvTorsoDesign& design, int64_t size) {
  for (const ConvLayerDesign& layer : design.layers) {
    if (size < layer.kernel) return 0;
    size = (size - layer.kernel) / layer.stride + 1;
  }
  return size;
}

absl::StatusOr<Torso> ParseTorso(absl::string_view name) {
  if (name == "auto") return Torso::kAuto;
  if (name == "mlp") return Torso::kMlp;
  for (const ConvTorsoDesign& design : Designs()) {
    if (name == design.name) return design.torso;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown torso \"", name, "\"; valid: ", TorsoNames()));
}

std::string TorsoNames() {
  std::vector<std::string> names = {"auto", "mlp"};
  for (const ConvTorsoDesign& design : Designs()) {
    names.push_back(design.name);
  }
  return absl::StrJoin(names, ", ");
}

std::string TorsoName(Torso torso) {
  if (torso == Torso::kAuto) return "auto";
  if (torso == Torso::kMlp) return "mlp";
  return FindConvTorsoDesign(torso)->name;
}

absl::StatusOr<Core> ParseCore(absl::string_view name) {
  if (name == "none") return Core::kNone;
  if (name == "gru") return Core::kGru;
  if (name == "lstm") return Core::kLstm;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown core \"", name, "\"; valid: none, gru, lstm"));
}

std::string CoreName(Core core) {
  switch (core) {
    case Core::kGru:
      return "gru";
    case Core::kLstm:
      return "lstm";
    case Core::kNone:
      break;
  }
  return "none";
}

absl::StatusOr<Torso> ResolveTorso(Torso torso, const EnvSpec& spec) {
  const std::vector<int64_t>& shape = spec.observation_shape;
  if (torso == Torso::kAuto) {
    if (shape.size() != 3) return Torso::kMlp;
    const int64_t side = std::min(shape[1], shape[2]);
    return side >= SmallestSide(*FindConvTorsoDesign(Torso::kNature))
               ? Torso::kNature
               : Torso::kMinAtar;
  }
  if (torso == Torso::kMlp) return torso;
  const ConvTorsoDesign& design = *FindConvTorsoDesign(torso);
  if (shape.size() != 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "torso ", design.name, " needs image observations; ", spec.name,
        " has vectors of ", spec.observation_size, " (use --torso=mlp)"));
  }
  if (ConvOutputSide(design, shape[1]) < 1 ||
      ConvOutputSide(design, shape[2]) < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "torso ", design.name, " needs frames of at least ",
        SmallestSide(design), "x", SmallestSide(design), " pixels; ", spec.name,
        " has ", absl::StrJoin(shape, "x"), " (use --torso=minatar)"));
  }
  return torso;
}

namespace {

// The spec of one image entry alone, for the torso rules of one image.
EnvSpec ImageSpec(const EnvSpec& spec, const ObservationKey& key) {
  EnvSpec image;
  image.name = absl::StrCat(spec.name, "[", key.name, "]");
  image.observation_size = key.size;
  image.observation_shape = key.shape;
  image.observation_high = key.high;
  return image;
}

}  // namespace

absl::StatusOr<Torso> DictImageTorso(const EnvSpec& spec,
                                     const ObservationKey& key) {
  const EnvSpec image = ImageSpec(spec, key);
  absl::StatusOr<Torso> torso = ResolveTorso(Torso::kAuto, image);
  if (!torso.ok()) return torso.status();
  // Auto picks by size alone; the smallest torso must still fit.
  return ResolveTorso(*torso, image);
}

absl::Status CheckDictNetwork(const NetworkConfig& config,
                              const EnvSpec& spec) {
  if (spec.observation_keys.empty()) return absl::OkStatus();
  const std::string what = absl::StrCat(spec.name, " has a Dict observation, ");
  if (config.torso != Torso::kAuto) {
    return absl::InvalidArgumentError(absl::StrCat(
        what,
        "whose images each get the torso --torso=auto picks for them; "
        "--torso=",
        TorsoName(config.torso), " does not apply"));
  }
  if (config.shared_torso) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, "whose torsos are not shared (--shared_torso)"));
  }
  if (config.recurrent()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, "which a recurrent --core does not take yet"));
  }
  for (const ObservationKey& key : spec.observation_keys) {
    if (!key.image()) continue;
    if (absl::StatusOr<Torso> torso = DictImageTorso(spec, key); !torso.ok()) {
      return torso.status();
    }
  }
  return absl::OkStatus();
}

absl::Status CheckNetworkConfig(const NetworkConfig& config,
                                const EnvSpec& spec) {
  if (!spec.observation_keys.empty()) return CheckDictNetwork(config, spec);
  const absl::StatusOr<Torso> torso = ResolveTorso(config.torso, spec);
  if (!torso.ok()) return torso.status();
  if (config.shared_torso && *torso == Torso::kMlp) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a shared torso needs a convolutional one, but '", spec.name,
        "' gets the mlp torso (--torso=", TorsoName(config.torso),
        "); share with --torso=minatar or nature on image observations"));
  }
  if (config.recurrent() && config.core_size < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--core_size must be >= 1 for --core=", CoreName(config.core)));
  }
  if (config.seq_len < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--seq_len must be >= 0 (0: whole segments), got ", config.seq_len));
  }
  return absl::OkStatus();
}

}  // namespace vantage
