#include "actor/envs/minatar/minatar_env.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/minatar/asterix.h"
#include "actor/envs/minatar/breakout.h"
#include "actor/envs/minatar/freeway.h"
#include "actor/envs/minatar/minatar_game.h"
#include "actor/envs/minatar/seaquest.h"
#include "actor/envs/minatar/space_invaders.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr double kStickyActionProbability = 0.1;
constexpr int64_t kMaxEpisodeSteps = 10000;
constexpr char kStateKind[] = "minatar_env";
constexpr uint32_t kStateVersion = 1;

// Cell colours for pictures, one per channel; where channels overlap the
// later one is drawn (as MinAtar's display does). Background black.
constexpr std::array<std::array<uint8_t, 3>, 10> kPalette = {{
    {230, 230, 230},
    {255, 196, 0},
    {90, 110, 140},
    {220, 60, 60},
    {60, 190, 90},
    {240, 120, 30},
    {170, 80, 220},
    {60, 170, 230},
    {250, 250, 110},
    {255, 105, 180},
}};

using GameFactory = std::function<std::unique_ptr<MinAtarGame>()>;

class MinAtarEnv : public Environment {
 public:
  MinAtarEnv(std::string name, GameFactory factory)
      : factory_(std::move(factory)), game_(factory_()) {
    spec_.name = std::move(name);
    spec_.observation_size = game_->channels() * kMinAtarCells;
    spec_.observation_shape = {game_->channels(), kMinAtarGridSize,
                               kMinAtarGridSize};
    spec_.observation_high = 1;
    spec_.discrete = true;
    spec_.action_size = kMinAtarActions;
    spec_.max_episode_steps = kMaxEpisodeSteps;
    // No physics: videos play 15 steps a second.
    spec_.control_dt = 1.0 / 15.0;
    grid_.resize(spec_.observation_size);
    // Saved before the first Reset, the state must replay like any other:
    // start from what Reset(seed 0) gives.
    random_.seed(seed_);
    game_->Reset(random_);
  }

  const EnvSpec& spec() const override { return spec_; }
  std::unique_ptr<MinAtarGame> MakeGame() const { return factory_(); }

  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override {
    if (absl::Status status = CheckObservationBuffer(spec_, observation);
        !status.ok()) {
      return status;
    }
    seed_ = seed;
    random_.seed(seed);
    game_->Reset(random_);
    last_action_ = 0;
    actions_.clear();
    needs_reset_ = false;
    Observe(observation);
    return absl::OkStatus();
  }

  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override {
    if (absl::Status status =
            CheckStep(spec_, needs_reset_, action, observation);
        !status.ok()) {
      return status;
    }
    const int chosen = static_cast<int>(action[0]);
    const GameStep step = Play(chosen);
    actions_.push_back(static_cast<char>(chosen));
    StepResult result;
    result.reward = step.reward;
    result.terminated = step.terminal;
    // The limit holds without the TimeLimit wrapper too, so a saved state
    // never outgrows what RestoreState accepts.
    result.truncated =
        !step.terminal &&
        static_cast<int64_t>(actions_.size()) == kMaxEpisodeSteps;
    if (result.terminated || result.truncated) needs_reset_ = true;
    Observe(observation);
    return result;
  }

  // The episode's seed and actions: replaying them rebuilds the game
  // exactly, so a saved state needs no per-game format and a hostile blob
  // can at worst name actions, which are checked.
  absl::StatusOr<std::string> SaveState() const override {
    StateWriter writer(kStateKind, kStateVersion);
    writer.PutBytes(spec_.name);
    writer.PutBool(needs_reset_);
    writer.PutU64(seed_);
    writer.PutBytes(actions_);
    writer.PutU64(GameFingerprint(*game_, last_action_));
    return std::move(writer).Finish();
  }

  absl::Status RestoreState(absl::string_view state) override {
    const std::string context = absl::StrCat(spec_.name, ": MinAtar state");
    StateReader reader(state, kStateKind, kStateVersion, context);
    reader.ExpectEqual("the environment", reader.GetBytes("name"), spec_.name);
    const bool needs_reset = reader.GetBool("needs_reset");
    const uint64_t seed = reader.GetU64("seed");
    const std::string actions(reader.GetBytes("actions"));
    const uint64_t fingerprint = reader.GetU64("fingerprint");
    if (absl::Status status = reader.Finish(); !status.ok()) return status;
    const auto invalid = [&](absl::string_view why) {
      return absl::InvalidArgumentError(absl::StrCat(context, ": ", why));
    };
    if (static_cast<int64_t>(actions.size()) > kMaxEpisodeSteps) {
      return invalid(absl::StrCat(actions.size(),
                                  " actions, more than an "
                                  "episode's ",
                                  kMaxEpisodeSteps));
    }
    for (char a : actions) {
      if (a < 0 || a >= kMinAtarActions) {
        return invalid(absl::StrCat("action ", static_cast<int>(a),
                                    " is not in [0, ", kMinAtarActions, ")"));
      }
    }
    // Replayed on a fresh game, swapped in only when it checks out.
    std::unique_ptr<MinAtarGame> game = factory_();
    std::mt19937_64 random(seed);
    int last_action = 0;
    game->Reset(random);
    bool ended = false;
    for (size_t i = 0; i < actions.size(); ++i) {
      ended = PlayOn(*game, random, last_action, actions[i]).terminal;
      if (ended && i + 1 < actions.size()) {
        return invalid("the game ends before its saved actions do");
      }
    }
    const bool at_limit =
        static_cast<int64_t>(actions.size()) == kMaxEpisodeSteps;
    if ((ended || at_limit) != needs_reset && !actions.empty()) {
      return invalid(needs_reset ? "the saved actions do not end the game, "
                                   "yet the state says the episode is over"
                                 : "the saved actions end the episode, yet "
                                   "the state says it goes on");
    }
    if (GameFingerprint(*game, last_action) != fingerprint) {
      return invalid(
          "replaying the saved actions does not give the saved game (a "
          "state saved by other rules, or corrupted)");
    }
    game_ = std::move(game);
    random_ = random;
    seed_ = seed;
    last_action_ = last_action;
    actions_ = actions;
    needs_reset_ = needs_reset;
    return absl::OkStatus();
  }

  absl::StatusOr<Frame> Render(int width, int height) override {
    if (width < 1 || height < 1) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": a picture needs at least 1 x 1 pixels, got ", width,
          " x ", height));
    }
    game_->Observe(absl::MakeSpan(grid_));
    Frame frame;
    frame.width = width;
    frame.height = height;
    frame.rgb.assign(3 * static_cast<size_t>(width) * height, 0);
    const int channels = game_->channels();
    for (int py = 0; py < height; ++py) {
      const int y = py * kMinAtarGridSize / height;
      for (int px = 0; px < width; ++px) {
        const int x = px * kMinAtarGridSize / width;
        for (int c = channels - 1; c >= 0; --c) {
          if (!grid_[Cell(c, y, x)]) continue;
          std::copy(
              kPalette[c].begin(), kPalette[c].end(),
              frame.rgb.begin() + 3 * (static_cast<size_t>(py) * width + px));
          break;
        }
      }
    }
    return frame;
  }

 private:
  // Sticky actions: one draw per step, before the game's own.
  static GameStep PlayOn(MinAtarGame& game, std::mt19937_64& random,
                         int& last_action, int chosen) {
    int played = chosen;
    if (UniformUnit(random) < kStickyActionProbability) played = last_action;
    last_action = played;
    return game.Act(static_cast<MinAtarAction>(played), random);
  }

  GameStep Play(int chosen) {
    return PlayOn(*game_, random_, last_action_, chosen);
  }

  void Observe(absl::Span<double> observation) {
    game_->Observe(absl::MakeSpan(grid_));
    std::copy(grid_.begin(), grid_.end(), observation.begin());
  }

  static uint64_t GameFingerprint(const MinAtarGame& game, int last_action) {
    std::string grid(game.channels() * kMinAtarCells, '\0');
    game.Observe(
        absl::MakeSpan(reinterpret_cast<uint8_t*>(grid.data()), grid.size()));
    grid.push_back(static_cast<char>(last_action));
    return Fingerprint(grid);
  }

  GameFactory factory_;
  std::unique_ptr<MinAtarGame> game_;
  EnvSpec spec_;
  std::mt19937_64 random_;
  uint64_t seed_ = 0;
  int last_action_ = 0;
  std::string actions_;
  bool needs_reset_ = true;
  std::vector<uint8_t> grid_;
};

absl::StatusOr<std::unique_ptr<Environment>> Make(std::string name,
                                                  GameFactory factory) {
  return std::unique_ptr<Environment>(
      new MinAtarEnv(std::move(name), std::move(factory)));
}

}  // namespace

std::unique_ptr<MinAtarGame> MakeBareGame(const Environment& env) {
  const auto* minatar = dynamic_cast<const MinAtarEnv*>(&env);
  return minatar == nullptr ? nullptr : minatar->MakeGame();
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarAsterix() {
  return Make("MinAtarAsterix", [] { return std::make_unique<Asterix>(true); });
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarBreakout() {
  return Make("MinAtarBreakout", [] { return std::make_unique<Breakout>(); });
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarFreeway() {
  return Make("MinAtarFreeway", [] { return std::make_unique<Freeway>(); });
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarSeaquest() {
  return Make("MinAtarSeaquest",
              [] { return std::make_unique<Seaquest>(true); });
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMinAtarSpaceInvaders() {
  return Make("MinAtarSpaceInvaders",
              [] { return std::make_unique<SpaceInvaders>(true); });
}

}  // namespace vantage
