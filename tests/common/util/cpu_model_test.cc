#include "common/util/cpu_model.h"

#include "gtest/gtest.h"

namespace vantage {
namespace {

TEST(CpuModelTest, NamesTheFirstProcessorsModel) {
  EXPECT_EQ(
      CpuModelFromCpuinfo("processor\t: 0\n"
                          "vendor_id\t: AuthenticAMD\n"
                          "model\t\t: 1\n"
                          "model name\t: AMD EPYC 7B13 64-Core Processor\n"
                          "processor\t: 1\n"
                          "model name\t: Another One\n"),
      "AMD EPYC 7B13 64-Core Processor");
  // ARM names no model: its implementer and part do.
  EXPECT_EQ(CpuModelFromCpuinfo("processor\t: 0\nCPU implementer\t: 0x41\n"
                                "CPU part\t: 0xd0c\n"),
            "implementer 0x41 part 0xd0c");
  EXPECT_EQ(CpuModelFromCpuinfo(""), "unknown");
  // Nothing a JSON string or a CSV field would need escaped.
  EXPECT_EQ(CpuModelFromCpuinfo("model name : Odd \"CPU\", v2\\x\n"),
            "Odd CPU v2x");
}

TEST(CpuModelTest, ThisMachineHasOne) { EXPECT_FALSE(CpuModel().empty()); }

}  // namespace
}  // namespace vantage
