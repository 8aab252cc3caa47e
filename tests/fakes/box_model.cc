#include "tests/fakes/box_model.h"

#include "absl/strings/str_cat.h"

namespace vantage {

std::string BoxModel(const std::string& custom) {
  return absl::StrCat(R"xml(
<mujoco model="box">
  <option timestep="0.01"/>
  <custom>)xml",
                      custom, R"xml(</custom>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 1"/>
    <body name="box" pos="0 0 0.5">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="x" gear="10" ctrllimited="true" ctrlrange="-1 1"/>
    <motor joint="z" gear="40" ctrllimited="true" ctrlrange="-1 1"/>
  </actuator>
</mujoco>)xml");
}

}  // namespace vantage
