#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_RECURRENT_CORE_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_RECURRENT_CORE_H_

// A GRU or LSTM cell over chunks of sequences as FlatActorCritic trains
// it, without autograd: the input projections of every step in one BLAS
// call, the hidden projection of each step in one, the gates in plain
// loops keeping what the backward pass needs, and backpropagation through
// time written out by hand (LibTorch's gate orders: r, z, n for the GRU,
// whose candidate is tanh(W_in x + b_in + r * (W_hn h + b_hn)); i, f, g, o
// for the LSTM). tests/learner/algorithms/flat_actor_critic_test.cc checks
// it against autograd.

#include <cstdint>
#include <vector>

#include "common/nn/network_config.h"

namespace vantage {

class FlatRecurrentCore {
 public:
  // Where the cell's weight_ih [G*H, inputs], weight_hh [G*H, H], bias_ih
  // and bias_hh [G*H] begin in the flat arrays.
  struct Offsets {
    int64_t weight_ih = 0;
    int64_t weight_hh = 0;
    int64_t bias_ih = 0;
    int64_t bias_hh = 0;
  };

  FlatRecurrentCore(Core core, int64_t inputs, int64_t hidden, Offsets offsets);

  int64_t inputs() const { return inputs_; }
  int64_t hidden() const { return hidden_; }
  // The hidden state, then an LSTM's cell state.
  int64_t state_size() const { return lstm_ ? 2 * hidden_ : hidden_; }

  // `steps` steps of `chunks` sequences, rows time-major (step t of chunk
  // j at t * chunks + j): `encoded` [rows, inputs], `starts` [rows]
  // (nonzero: an episode starts at the row's step, the state is zeroed
  // before it), `states` [chunks, state_size()] the chunks' start states.
  // All arrays must stay unchanged until Backward.
  void Forward(const float* parameters, const float* encoded,
               const uint8_t* starts, const float* states, int64_t steps,
               int64_t chunks);
  // The hidden state after every step [rows, hidden()].
  const float* features() const { return features_.data(); }

  // For d loss / d features [rows, hidden()]: writes the cell's gradients
  // into `gradients` (its four ranges, overwritten) and d loss / d encoded
  // into `d_encoded` [rows, inputs()]. The start states get none.
  void Backward(const float* parameters, const float* d_features,
                float* gradients, float* d_encoded);

 private:
  int64_t gates() const { return (lstm_ ? 4 : 3) * hidden_; }
  // Forward's steps: the states step t reads (zeroed at episode starts)
  // with the hidden projection's bias; one row's gates from its hidden
  // projection `p`.
  void ReadStates(int64_t t, const float* states, const float* bias_hh);
  void Activate(int64_t row, const float* p);
  // Backward's steps: one row's gate gradients; one step's hidden weights'
  // gradient and the state gradient carried back.
  void RowGradients(int64_t row, int64_t j, const float* d_features);
  void StepBackward(int64_t t, const float* parameters, float* gradients);

  const bool lstm_;
  const int64_t inputs_;
  const int64_t hidden_;
  const Offsets offsets_;

  // The last Forward's shape and inputs.
  int64_t steps_ = 0;
  int64_t chunks_ = 0;
  const float* encoded_ = nullptr;
  const uint8_t* starts_ = nullptr;
  // Per row: the input projections [gates], the state the step read (zeroed
  // at a start) [state], the gates' activations [gates] (GRU: r, z, n; LSTM:
  // i, f, g, o), the GRU's hidden candidate term W_hn h + b_hn [H] or the
  // LSTM's tanh(c) [H], and the features.
  std::vector<float> projected_, read_, activations_, extra_, features_;
  std::vector<float> cells_;  // the LSTM's cell state after each step
  // Backward's scratch: gate gradients per row, the carried state gradient,
  // one step's hidden projection.
  std::vector<float> gate_gradients_, carry_, next_carry_, step_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_RECURRENT_CORE_H_
