#include "learner/exploration/ex2_bonus.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "common/nn/networks.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/exploration/exemplar_model.h"
#include "learner/exploration/flat_exemplar_model.h"
#include "learner/exploration/replay_pool.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

EnvSpec PlaneSpec() {
  EnvSpec spec;
  spec.name = "Plane";
  spec.observation_size = 2;
  spec.action_size = 1;
  spec.action_low = {-2.0};
  spec.action_high = {2.0};
  return spec;
}

// One rollout whose T states are `states` [T, 2], with zero rewards.
Rollout RolloutOf(const at::Tensor& states) {
  const int64_t t = states.size(0);
  Rollout rollout;
  rollout.observations = at::cat({states, states.slice(0, t - 1)});
  rollout.actions = at::zeros({t, 1});
  rollout.rewards = at::zeros({t});
  rollout.terminated = at::zeros({t}, at::kBool);
  rollout.truncated = at::zeros({t}, at::kBool);
  return rollout;
}

// `n` copies of the rows of `states` [k, 2], the i-th with probability
// `weights[i]`.
at::Tensor Draw(int64_t n, const at::Tensor& states,
                const std::vector<double>& weights, at::Generator& generator) {
  const at::Tensor index = at::multinomial(at::tensor(weights, at::kDouble), n,
                                           /*replacement=*/true, generator);
  return states.index_select(0, index);
}

Ex2Config SmallConfig() {
  Ex2Config config;
  config.hidden = {32};
  config.feature_dim = 16;
  config.learning_rate = 1e-3;
  config.kl_weight = 0.1;
  config.bonus_coeff = 1.0;
  config.train_iterations = 300;
  config.first_train_iterations = 1500;
  config.replay_min = 1000;
  config.replay_size = 5000;
  config.batch_size = 128;
  config.use_actions = false;
  return config;
}

void SetAllParameters(torch::nn::Module& module, double value) {
  at::NoGradGuard no_grad;
  for (at::Tensor& p : module.parameters()) p.fill_(value);
}

TEST(ReplayPoolTest, KeepsTheNewestRowsAndCountsEveryRow) {
  ReplayPool pool(/*capacity=*/5, /*width=*/1);
  pool.Add(at::arange(3, at::kFloat).reshape({3, 1}));
  EXPECT_EQ(pool.size(), 3);
  pool.Add(at::arange(3, 7, at::kFloat).reshape({4, 1}));
  EXPECT_EQ(pool.size(), 5);
  EXPECT_EQ(pool.total_added(), 7);
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(1);
  const at::Tensor sample = pool.Sample(2000, generator);
  // Rows 0 and 1 were pushed out; 2..6 are all drawn.
  EXPECT_EQ(sample.min().item<float>(), 2.0f);
  EXPECT_EQ(sample.max().item<float>(), 6.0f);
  EXPECT_EQ(std::get<0>(at::_unique(sample)).numel(), 5);
  // More rows than it holds at once: only the last ones stay.
  pool.Add(at::arange(10, 22, at::kFloat).reshape({12, 1}));
  EXPECT_EQ(pool.Sample(2000, generator).min().item<float>(), 17.0f);
  EXPECT_EQ(pool.total_added(), 19);
}

// A pool's rows through a checkpoint archive into `into`.
absl::Status SaveAndLoad(const ReplayPool& from, ReplayPool& into) {
  torch::serialize::OutputArchive out;
  from.Save(out, "pool");
  std::ostringstream bytes;
  out.save_to(bytes);
  torch::serialize::InputArchive in;
  std::istringstream stream(bytes.str());
  in.load_from(stream);
  return into.Load(in, "pool");
}

TEST(ReplayPoolTest, SavedPoolLoadsBackAndBadOnesAreRefused) {
  ReplayPool pool(4, 2);
  pool.Add(at::arange(12, at::kFloat).reshape({6, 2}));
  ReplayPool copy(4, 2);
  ASSERT_TRUE(SaveAndLoad(pool, copy).ok());
  EXPECT_EQ(copy.total_added(), 6);
  at::Generator a = at::make_generator<at::CPUGeneratorImpl>(3);
  at::Generator b = at::make_generator<at::CPUGeneratorImpl>(3);
  EXPECT_TRUE(copy.Sample(50, a).equal(pool.Sample(50, b)));
  // Another width: refused, naming both shapes.
  ReplayPool wider(4, 3);
  const absl::Status status = SaveAndLoad(pool, wider);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("4 rows of 2"));
  // Non-finite rows are refused.
  ReplayPool poisoned(4, 2);
  poisoned.Add(at::full({2, 2}, std::nanf("")));
  EXPECT_THAT(std::string(SaveAndLoad(poisoned, copy).message()),
              HasSubstr("non-finite"));
}

TEST(ReplayPoolTest, ByteObservationsArePooledAsBytes) {
  constexpr int64_t kHigh = 255;
  const at::Tensor frames =
      at::randint(kHigh + 1, {6, 5}, at::TensorOptions(at::kByte));
  ReplayPool pool(4, 5, kHigh);
  pool.Add(frames);
  EXPECT_EQ(pool.dtype(), at::kByte);
  at::Generator a = at::make_generator<at::CPUGeneratorImpl>(3);
  const at::Tensor sample = pool.Sample(20, a);
  EXPECT_EQ(sample.scalar_type(), at::kByte);
  ReplayPool copy(4, 5, kHigh);
  ASSERT_TRUE(SaveAndLoad(pool, copy).ok());
  at::Generator b = at::make_generator<at::CPUGeneratorImpl>(3);
  EXPECT_TRUE(copy.Sample(20, b).equal(sample));

  // A float pool of the frames as the networks see them (as every pool
  // held them before byte pools) draws the same rows, and the networks see
  // the byte pool's exactly as those.
  EnvSpec spec;
  spec.observation_size = 5;
  spec.observation_high = kHigh;
  ReplayPool legacy(4, 5);
  legacy.Add(NetworkInputs(spec, frames));
  at::Generator c = at::make_generator<at::CPUGeneratorImpl>(3);
  EXPECT_TRUE(NetworkInputs(spec, sample).equal(legacy.Sample(20, c)));
  // Its checkpoint loaded into a byte pool: the same bytes.
  ReplayPool converted(4, 5, kHigh);
  ASSERT_TRUE(SaveAndLoad(legacy, converted).ok());
  c = at::make_generator<at::CPUGeneratorImpl>(3);
  EXPECT_TRUE(converted.Sample(20, c).equal(sample));

  // Floats that are no scaled bytes, and bytes above the run's highest
  // value, are refused by name; the pool keeps what it had.
  ReplayPool vectors(4, 5);
  vectors.Add(at::full({2, 5}, 0.3f));
  absl::Status status = SaveAndLoad(vectors, converted);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("not observations of 0..255 scaled by 1/255"));
  ReplayPool brighter(4, 5, kHigh);
  brighter.Add(at::full({2, 5}, 9, at::kByte));
  ReplayPool dimmer(4, 5, /*byte_high=*/4);
  status = SaveAndLoad(brighter, dimmer);
  EXPECT_THAT(std::string(status.message()), HasSubstr("values above 4"));
  at::Generator d = at::make_generator<at::CPUGeneratorImpl>(3);
  EXPECT_TRUE(converted.Sample(20, d).equal(sample));
}

// With every weight 0 the latents are N(0, I) draws and D = 1/2 whatever
// the noise: the loss is log 2. A mean head biased to c adds, per latent
// dimension of both encoders, KL = c^2 / 2.
TEST(ExemplarModelTest, LossAndBonusMatchClosedForms) {
  Ex2Config config = SmallConfig();
  config.hidden = {8, 8};
  config.feature_dim = 3;
  ExemplarModel model(2, config);
  SetAllParameters(*model, 0.0);
  at::Generator noise = at::make_generator<at::CPUGeneratorImpl>(5);
  const at::Tensor x = at::randn({10, 2});
  ExemplarLoss loss = ComputeExemplarLoss(*model, x, x.flip(0), 0.5, noise);
  EXPECT_NEAR(loss.loss.item<double>(), std::log(2.0), 1e-6);
  const double c = 0.7;
  {
    at::NoGradGuard no_grad;
    for (auto& item : model->named_parameters()) {
      if (item.key().find("mean.layers.2.bias") != std::string::npos) {
        item.value().fill_(c);
      }
    }
  }
  loss = ComputeExemplarLoss(*model, x, x.flip(0), 0.5, noise);
  EXPECT_NEAR(loss.loss.item<double>(),
              std::log(2.0) + 0.5 * 2 * config.feature_dim * c * c / 2, 1e-5);
  // D(x, x) = sigmoid(b) from the discriminator's output bias b, so the
  // bonus log(D / (1 - D)) is b itself, clipped where D is.
  for (double b : {-3.0, 0.0, 2.5, 40.0}) {
    {
      at::NoGradGuard no_grad;
      for (auto& item : model->named_parameters()) {
        if (item.key() == "discriminator.layers.2.bias") item.value().fill_(b);
      }
    }
    const double expected = std::min(b, std::log((1 - 1e-5) / 1e-5));
    EXPECT_NEAR(NoveltyBonus(*model, x).mean().item<double>(), expected, 3e-3)
        << b;
  }
}

// The point of the model. Fitted on batches of two states, one nine times
// as frequent as the other, D(x, x) approaches P(x) / (P(x) + P(x)^2)
// (about 0.53 and 0.91): the rare state earns the larger bonus. When a
// batch brings a third state the pool has never held, D(x, x) of it
// approaches 1: the largest bonus of all. A weak KL weight, so that the
// few nats the two-state task offers are worth encoding.
TEST(Ex2BonusTest, RareStatesEarnMoreThanFrequentOnesAndNewOnesMost) {
  at::manual_seed(0);
  Ex2Config config = SmallConfig();
  config.kl_weight = 1e-3;
  config.train_iterations = 1000;
  Ex2Bonus ex2(config, PlaneSpec(), 11, SoloReplicaGroup());
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(2);
  const at::Tensor states =
      at::tensor({0.0f, 0.0f, 1.0f, 1.0f, -1.0f, 1.5f}).reshape({3, 2});
  const auto bonus = [&](int i) {
    return NoveltyBonus(ex2.model(), states.slice(0, i, i + 1)).item<double>();
  };
  // Pool sizes before each: 0, 600, 1200 (the first fit).
  for (int batch = 0; batch < 3; ++batch) {
    std::vector<Rollout> rollouts = {
        RolloutOf(Draw(600, states, {0.9, 0.1, 0.0}, generator))};
    const ExplorationStats stats = ex2.ShapeRewards(rollouts);
    ex2.Commit();
    if (batch == 2) {
      EXPECT_EQ(stats.fit_steps, 1500);
      EXPECT_GT(stats.model_accuracy, 0.55);
    }
  }
  EXPECT_NEAR(bonus(0), std::log(0.53 / 0.47), 0.3);
  EXPECT_NEAR(bonus(1), std::log(0.91 / 0.09), 0.6);
  std::vector<Rollout> rollouts = {
      RolloutOf(Draw(600, states, {0.8, 0.1, 0.1}, generator))};
  ex2.ShapeRewards(rollouts);
  EXPECT_LT(bonus(0) + 1.0, bonus(1));
  EXPECT_LT(bonus(1) + 1.0, bonus(2));
  // The rewards carry it: the new state's steps gain the most.
  const at::Tensor rewards = rollouts[0].rewards;
  const at::Tensor is_new =
      rollouts[0].observations.slice(0, 0, 600).select(1, 0).lt(-0.5);
  EXPECT_GT(rewards.masked_select(is_new).min().item<double>(),
            rewards.masked_select(is_new.logical_not()).max().item<double>());
}

// The model sees the actions the environment executes: a continuous one
// clipped to its bounds and scaled to [-1, 1], so that a policy sample far
// beyond them is no rarer than one at the bound.
TEST(Ex2BonusTest, ActionInputsAreTheExecutedActionsScaled) {
  Ex2Config config = SmallConfig();
  config.use_actions = true;
  Ex2Bonus ex2(config, PlaneSpec(), 1, SoloReplicaGroup());
  Rollout rollout = RolloutOf(at::zeros({4, 2}));
  rollout.actions = at::tensor({-9.0f, -1.0f, 1.5f, 30.0f}).reshape({4, 1});
  const at::Tensor inputs = ex2.Inputs({rollout});
  ASSERT_EQ(inputs.sizes(), (std::vector<int64_t>{4, 3}));
  const std::vector<float> expected = {-1.0f, -0.5f, 0.75f, 1.0f};
  for (int64_t i = 0; i < 4; ++i) {
    EXPECT_FLOAT_EQ(inputs[i][2].item<float>(), expected[i]) << i;
  }
}

// EX2's maze model (hidden 16-16, latent 8, KL weight 0.01, 1000 Adam
// steps an update, 5000 the first) on states alone, fed what a maze agent
// that explores produces: each batch covers a strip wider than the last.
// The bonus ranks a region never visited above the newest strip (seen in
// one batch) above the oldest (seen in every batch), and the discriminator
// does not saturate.
TEST(Ex2BonusTest, OnAWideningStreamNovelStatesEarnTheMost) {
  at::manual_seed(0);
  Ex2Config config;
  config.hidden = {16, 16};
  config.feature_dim = 8;
  config.kl_weight = 0.01;
  config.bonus_coeff = 0.01;
  config.train_iterations = 1000;
  config.first_train_iterations = 5000;
  config.replay_min = 4000;
  config.replay_size = 200000;
  config.use_actions = false;
  Ex2Bonus ex2(config, PlaneSpec(), 5, SoloReplicaGroup());
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(9);
  const auto strip = [&](double x_low, double x_high, int64_t n) {
    const at::Tensor u = at::rand({n, 2}, generator);
    return at::stack({x_low + (x_high - x_low) * u.select(1, 0),
                      -0.3 + 0.6 * u.select(1, 1)},
                     1);
  };
  constexpr int kBatches = 6;
  ExplorationStats stats;
  for (int k = 0; k < kBatches; ++k) {
    std::vector<Rollout> rollouts = {
        RolloutOf(strip(-0.3, -0.3 + 0.06 * (k + 1), 4000))};
    stats = ex2.ShapeRewards(rollouts);
    ex2.Commit();
  }
  const auto mean_bonus = [&](double x_low, double x_high) {
    return NoveltyBonus(ex2.model(), strip(x_low, x_high, 500))
        .mean()
        .item<double>();
  };
  const double oldest = mean_bonus(-0.3, -0.24);
  const double newest =
      mean_bonus(-0.3 + 0.06 * (kBatches - 1), -0.3 + 0.06 * kBatches);
  const double novel = mean_bonus(0.2, 0.3);
  EXPECT_LT(oldest + 0.3, newest) << oldest << " " << newest;
  EXPECT_LT(newest + 0.3, novel) << newest << " " << novel;
  EXPECT_LT(stats.model_accuracy, 0.95);
}

// EX2's SiameseConv with its Doom script's sizes (32x32 RGB frames, hidden
// 32, latent 16): per encoder two convolutions (3 -> 16 and 16 -> 16
// filters of 4x4, full padding: 32 -> 18 -> 11) and heads over the
// 16 x 11 x 11 features and the action, if modelled.
TEST(Ex2ConvModelTest, LayersAreEx2sSiameseConv) {
  Ex2Config config;
  config.hidden = {32};
  config.feature_dim = 16;
  config.encoder = "conv";
  const std::vector<int64_t> frames = {3, 32, 32};
  for (const int64_t actions : {0, 3}) {
    SCOPED_TRACE(actions);
    ExemplarModel model(3 * 32 * 32 + actions, config, frames);
    const auto count = [](const torch::nn::Module& module) {
      int64_t n = 0;
      for (const at::Tensor& p : module.parameters()) n += p.numel();
      return n;
    };
    const ExemplarEncoderImpl& encoder = *model->exemplar_encoder();
    EXPECT_TRUE(encoder.trunk().is_empty());
    const int64_t convolutions = (3 * 16 * 16 + 16) + (16 * 16 * 16 + 16);
    const int64_t head = (16 * 11 * 11 + actions) * 32 + 32 + 32 * 16 + 16;
    EXPECT_EQ(count(encoder), convolutions + 2 * head);
    EXPECT_EQ(count(*model->discriminator()), 32 * 32 + 32 + 32 + 1);
    const at::Tensor x = at::rand({5, 3 * 32 * 32 + actions});
    const ExemplarOutput out = model->forward(x, x.flip(0), nullptr);
    EXPECT_EQ(out.probability.sizes(), (std::vector<int64_t>{5}));
    EXPECT_EQ(out.kl.sizes(), (std::vector<int64_t>{5}));
    // The flat fit writes out MLP encoders only.
    EXPECT_EQ(FlatExemplarModel::Create(*model, config, model->parameters())
                  .status()
                  .code(),
              absl::StatusCode::kUnimplemented);
  }
}

// 16x16 grey frames, each a 2x2 bright square at (row, column) on black:
// a maze agent seen from above. Each batch reaches two columns further
// right than the last. The convolutional model ranks the newest frames
// (columns 6-7, in one batch) and those just beyond them (8-9, never a
// square's column) above the oldest (0-1, in every batch). Frames whose
// pixels no batch ever lit (columns 12-14) are not ranked reliably (from
// -1.9 to +2.0 over four seeds; the MLP: -0.4): the model is fitted where
// the data is, and its extrapolation is not EX2's to promise.
TEST(Ex2ConvModelTest, OnAWideningStreamOfFramesRarerFramesEarnMore) {
  at::manual_seed(0);
  EnvSpec spec;
  spec.name = "Squares";
  spec.observation_size = 16 * 16;
  spec.observation_shape = {1, 16, 16};
  spec.observation_high = 255;
  spec.action_size = 1;
  spec.action_low = {-1.0};
  spec.action_high = {1.0};
  Ex2Config config = SmallConfig();
  config.encoder = "conv";
  config.kl_weight = 0.01;
  config.first_train_iterations = 600;
  config.train_iterations = 300;
  config.replay_min = 2000;
  config.replay_size = 20000;
  Ex2Bonus ex2(config, spec, 5, SoloReplicaGroup());
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(9);
  const auto squares = [&](int64_t column_low, int64_t column_high, int64_t n) {
    const at::Tensor rows = at::randint(0, 15, {n}, generator);
    const at::Tensor columns =
        at::randint(column_low, column_high + 1, {n}, generator);
    at::Tensor frames = at::zeros({n, 16, 16}, at::kByte);
    for (int64_t i = 0; i < n; ++i) {
      const int64_t r = rows[i].item<int64_t>();
      const int64_t c = columns[i].item<int64_t>();
      frames[i].narrow(0, r, 2).narrow(1, c, 2).fill_(255);
    }
    return frames.reshape({n, 16 * 16});
  };
  constexpr int kBatches = 4;
  for (int k = 0; k < kBatches; ++k) {
    std::vector<Rollout> rollouts = {RolloutOf(squares(0, 2 * k + 1, 2000))};
    ex2.ShapeRewards(rollouts);
    ex2.Commit();
  }
  // Frames are pooled as the bytes they arrived in.
  EXPECT_EQ(ex2.pool().dtype(), at::kByte);
  EXPECT_EQ(ex2.pool().size(), kBatches * 2000);
  const auto mean_bonus = [&](int64_t column_low, int64_t column_high) {
    const at::Tensor frames = squares(column_low, column_high, 500);
    return NoveltyBonus(ex2.model(), frames.to(at::kFloat) / 255.0)
        .mean()
        .item<double>();
  };
  const double oldest = mean_bonus(0, 1);
  const double newest = mean_bonus(2 * kBatches - 2, 2 * kBatches - 1);
  const double beyond = mean_bonus(2 * kBatches, 2 * kBatches + 1);
  EXPECT_LT(oldest + 0.3, newest) << oldest << " " << newest;
  EXPECT_LT(oldest + 0.3, beyond) << oldest << " " << beyond;
}

// EX2's order: a batch fits only once the pool has seen replay_min states
// before it, but its bonus counts the batch itself; the first fit is the
// long one; rewards gain bonus_coeff x (b - median b).
TEST(Ex2BonusTest, FitsAndShapesOnEx2sSchedule) {
  at::manual_seed(0);
  Ex2Config config = SmallConfig();
  config.replay_min = 1000;
  config.bonus_coeff = 0.25;
  config.first_train_iterations = 40;
  config.train_iterations = 10;
  Ex2Bonus ex2(config, PlaneSpec(), 3, SoloReplicaGroup());
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(4);
  std::vector<int64_t> fits;
  std::vector<double> bonuses;
  for (int batch = 0; batch < 4; ++batch) {
    std::vector<Rollout> rollouts = {RolloutOf(at::randn({300, 2}, generator)),
                                     RolloutOf(at::randn({300, 2}, generator))};
    const ExplorationStats stats = ex2.ShapeRewards(rollouts);
    fits.push_back(stats.fit_steps);
    bonuses.push_back(stats.mean_bonus);
    const at::Tensor added =
        at::cat({rollouts[0].rewards, rollouts[1].rewards});
    if (batch == 0) {
      EXPECT_TRUE(added.equal(at::zeros({600}))) << "no bonus before the pool";
      EXPECT_TRUE(std::isnan(stats.model_loss));
      EXPECT_EQ(stats.bonus_std, 0.0);
    } else {
      // Centred on the median: as many steps above it as below.
      EXPECT_EQ((added > 0).sum().item<int64_t>(),
                (added < 0).sum().item<int64_t>());
      // The bonus of the model as fitted on this batch (numpy's median of
      // an even count: the mean of the middle two).
      const at::Tensor raw = NoveltyBonus(ex2.model(), ex2.Inputs(rollouts));
      const at::Tensor sorted = std::get<0>(raw.sort());
      const double median =
          0.5 * (sorted[299].item<double>() + sorted[300].item<double>());
      EXPECT_TRUE(at::allclose(added, 0.25 * (raw - median), 1e-5, 1e-6));
      EXPECT_NEAR(stats.mean_bonus, raw.mean().item<double>(), 1e-6);
      EXPECT_NEAR(stats.bonus_std, raw.std(/*unbiased=*/false).item<double>(),
                  1e-6);
    }
    ex2.Commit();
    EXPECT_EQ(ex2.pool().total_added(), 600 * (batch + 1));
  }
  // Pool sizes before each batch: 0, 600, 1200, 1800.
  EXPECT_THAT(fits, ::testing::ElementsAre(0, 0, 40, 10));
  EXPECT_EQ(bonuses[0], 0.0);
  EXPECT_NE(bonuses[1], 0.0);  // the untrained model's, as in the reference
}

TEST(Ex2BonusTest, SameSeedSameBonusesAndASavedModelContinuesExactly) {
  const auto batches = [] {
    std::vector<std::vector<Rollout>> all;
    at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(9);
    for (int i = 0; i < 5; ++i) {
      all.push_back({RolloutOf(at::randn({400, 2}, generator))});
    }
    return all;
  };
  Ex2Config config = SmallConfig();
  config.replay_min = 500;
  config.replay_size = 900;  // wraps around
  config.first_train_iterations = 30;
  config.train_iterations = 20;
  at::manual_seed(1);
  Ex2Bonus whole(config, PlaneSpec(), 8, SoloReplicaGroup());
  std::vector<at::Tensor> expected;
  for (std::vector<Rollout>& rollouts : batches()) {
    whole.ShapeRewards(rollouts);
    whole.Commit();
    expected.push_back(rollouts[0].rewards);
  }
  at::manual_seed(1);
  Ex2Bonus first(config, PlaneSpec(), 8, SoloReplicaGroup());
  std::vector<std::vector<Rollout>> inputs = batches();
  for (int i = 0; i < 3; ++i) {
    first.ShapeRewards(inputs[i]);
    first.Commit();
    EXPECT_TRUE(inputs[i][0].rewards.equal(expected[i])) << i;
  }
  torch::serialize::OutputArchive out;
  first.Save(out, "ex2");
  std::ostringstream bytes;
  out.save_to(bytes);
  at::manual_seed(99);  // other initial weights, all overwritten
  Ex2Bonus resumed(config, PlaneSpec(), 1234, SoloReplicaGroup());
  torch::serialize::InputArchive in;
  std::istringstream stream(bytes.str());
  in.load_from(stream);
  ASSERT_TRUE(resumed.Load(in, "ex2").ok());
  for (int i = 3; i < 5; ++i) {
    resumed.ShapeRewards(inputs[i]);
    resumed.Commit();
    EXPECT_TRUE(inputs[i][0].rewards.equal(expected[i])) << i;
  }
  // A model of other inputs (actions too) does not load it.
  config.use_actions = true;
  Ex2Bonus other(config, PlaneSpec(), 8, SoloReplicaGroup());
  torch::serialize::InputArchive again;
  std::istringstream stream2(bytes.str());
  again.load_from(stream2);
  const absl::Status status = other.Load(again, "ex2");
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("replay pool"));
}

// The fused Adam fits the model as torch::optim::Adam does:
// from the same weights, draws and batches, the same parameters to 1e-5
// of each tensor's scale and the same bonuses; and a checkpoint of one
// continues on the other.
TEST(Ex2BonusTest, TheFusedAdamFitsAsTorchsAdam) {
  Ex2Config config = SmallConfig();
  config.replay_min = 500;
  config.first_train_iterations = 60;
  config.train_iterations = 30;
  at::manual_seed(2);
  Ex2Bonus fused(config, PlaneSpec(), 5, SoloReplicaGroup(), Ex2Fit::kAutograd);
  at::manual_seed(2);
  Ex2Bonus reference(config, PlaneSpec(), 5, SoloReplicaGroup(),
                     Ex2Fit::kTorch);
  const auto expect_same = [](Ex2Bonus& a, Ex2Bonus& b, const char* when) {
    const std::vector<at::Tensor> pa = a.parameters();
    const std::vector<at::Tensor> pb = b.parameters();
    ASSERT_EQ(pa.size(), pb.size());
    for (size_t i = 0; i < pa.size(); ++i) {
      const double scale = std::max(1e-12, pb[i].abs().max().item<double>());
      EXPECT_LE((pa[i] - pb[i]).abs().max().item<double>() / scale, 1e-5)
          << when << ": parameter " << i;
    }
  };
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(6);
  const at::Tensor initial = fused.parameters()[0].clone();
  for (int batch = 0; batch < 4; ++batch) {
    const at::Tensor states = at::randn({300, 2}, generator);
    std::vector<Rollout> a = {RolloutOf(states)};
    std::vector<Rollout> b = {RolloutOf(states)};
    const ExplorationStats sa = fused.ShapeRewards(a);
    const ExplorationStats sb = reference.ShapeRewards(b);
    EXPECT_EQ(sa.fit_steps, sb.fit_steps);
    EXPECT_TRUE(at::allclose(a[0].rewards, b[0].rewards, 1e-4, 1e-6))
        << "batch " << batch;
    fused.Commit();
    reference.Commit();
    expect_same(fused, reference, "fitted");
  }
  EXPECT_FALSE(at::allclose(fused.parameters()[0], initial));

  // The fused one's checkpoint, continued by torch's Adam.
  torch::serialize::OutputArchive out;
  fused.Save(out, "ex2");
  std::ostringstream bytes;
  out.save_to(bytes);
  Ex2Bonus resumed(config, PlaneSpec(), 77, SoloReplicaGroup(), Ex2Fit::kTorch);
  torch::serialize::InputArchive in;
  std::istringstream stream(bytes.str());
  in.load_from(stream);
  ASSERT_TRUE(resumed.Load(in, "ex2").ok());
  const at::Tensor states = at::randn({300, 2}, generator);
  std::vector<Rollout> a = {RolloutOf(states)};
  std::vector<Rollout> b = {RolloutOf(states)};
  fused.ShapeRewards(a);
  resumed.ShapeRewards(b);
  expect_same(fused, resumed, "resumed");
}

// A bonus fitted on the flat model (the default) shapes the rewards as one
// fitted through autograd does, from the same weights, draws and batches
// (both step with the fused Adam; only rounding differs).
TEST(Ex2BonusTest, TheFlatModelFitsAsAutogradDoes) {
  Ex2Config config = SmallConfig();
  config.replay_min = 500;
  config.first_train_iterations = 60;
  config.train_iterations = 30;
  at::manual_seed(5);
  Ex2Bonus flat(config, PlaneSpec(), 9, SoloReplicaGroup());
  at::manual_seed(5);
  Ex2Bonus autograd(config, PlaneSpec(), 9, SoloReplicaGroup(),
                    Ex2Fit::kAutograd);
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(6);
  for (int batch = 0; batch < 4; ++batch) {
    const at::Tensor states = at::randn({300, 2}, generator) * (batch + 1);
    std::vector<Rollout> a = {RolloutOf(states)};
    std::vector<Rollout> b = {RolloutOf(states)};
    const ExplorationStats sa = flat.ShapeRewards(a);
    const ExplorationStats sb = autograd.ShapeRewards(b);
    flat.Commit();
    autograd.Commit();
    EXPECT_EQ(sa.fit_steps, sb.fit_steps);
    if (sa.fit_steps > 0) EXPECT_NEAR(sa.model_loss, sb.model_loss, 1e-3);
    EXPECT_LE((a[0].rewards - b[0].rewards).abs().max().item<double>(),
              1e-3 * std::max(1.0, b[0].rewards.abs().max().item<double>()))
        << "batch " << batch;
  }
}

TEST(Ex2ConfigTest, RulesNameTheirField) {
  Ex2Config config;
  EXPECT_TRUE(config.Validate().ok());
  config.kl_weight = -1;
  EXPECT_THAT(std::string(config.Validate().message()),
              HasSubstr("ex2.kl_weight"));
  config = Ex2Config();
  config.hidden = {};
  EXPECT_THAT(std::string(config.Validate().message()),
              HasSubstr("ex2.hidden"));
  config = Ex2Config();
  config.replay_size = int64_t{1} << 40;
  EXPECT_THAT(std::string(config.Validate().message()),
              HasSubstr("ex2.replay_size"));
}

}  // namespace
}  // namespace vantage
