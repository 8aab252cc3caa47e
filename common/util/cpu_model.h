#ifndef VANTAGE_COMMON_UTIL_CPU_MODEL_H_
#define VANTAGE_COMMON_UTIL_CPU_MODEL_H_

#include <string>

namespace vantage {

// This machine's CPU model as /proc/cpuinfo names it ("AMD EPYC 7B13",
// "Intel(R) Xeon(R) CPU @ 2.20GHz"; on ARM its implementer and part), for
// telling apart results of runs on different machines; "unknown" if the
// file says nothing.
std::string CpuModel();

// The same from the text of a /proc/cpuinfo.
std::string CpuModelFromCpuinfo(const std::string& cpuinfo);

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_CPU_MODEL_H_
