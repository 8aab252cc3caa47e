#ifndef VANTAGE_TESTS_FAKES_BOX_MODEL_H_
#define VANTAGE_TESTS_FAKES_BOX_MODEL_H_

// A small MJCF model (a box on two slide joints, two motors) whose
// <custom> block is `custom`: what the MJCF environment tests and the MJCF
// fuzzer feed to MakeMjcfEnv.

#include <string>

namespace vantage {

std::string BoxModel(const std::string& custom);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_BOX_MODEL_H_
