#ifndef VANTAGE_ACTOR_ENVS_CHOICE_LIT_BUTTONS_H_
#define VANTAGE_ACTOR_ENVS_CHOICE_LIT_BUTTONS_H_

// LitButtons, a task where most actions are illegal: a panel of `buttons`
// buttons of which `lit` are lit at each step, each lit one showing a value
// in [0, 1); pressing a lit button earns its value. Observations are
// [lit flags (buttons), values (buttons, 0 where unlit)]; which buttons
// are lit and their values are drawn afresh every step, and an episode is
// `steps` presses. Pressing the best lit button earns about
// steps * lit / (lit + 1); any lit one, steps / 2.
//
// With `masked` (the default) the environment gives action masks (only
// the lit buttons are legal) and refuses an unlit press; without, an unlit
// press costs 1 and changes nothing else: the same task for a policy that
// must learn what is legal by being punished.
//
// Options (`LitButtons:buttons=16,lit=2,masked=false`): buttons (>= 2,
// default 32), lit (>= 1, at most buttons, default 3), steps (>= 1,
// default 16), masked (default true) and dict (default false: the same
// values as a Dict observation of "lit" and "values", the native form of a
// structured observation).

#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "actor/envs/env_options.h"
#include "common/env/environment.h"

namespace vantage {

absl::StatusOr<std::unique_ptr<Environment>> MakeLitButtons(
    const EnvName& name);
std::vector<EnvOptionInfo> LitButtonsOptions();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_CHOICE_LIT_BUTTONS_H_
