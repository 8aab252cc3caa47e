#ifndef VANTAGE_COMMON_UTIL_MALLOC_SETTINGS_H_
#define VANTAGE_COMMON_UTIL_MALLOC_SETTINGS_H_

// glibc's malloc hands every freed block above its mmap threshold (32 MiB
// at most) back to the kernel, and trims the top of its heap past 128 KiB
// of free memory. A run on frames allocates and frees batches of tens of
// megabytes every update (4000 frames of 3 x 42 x 42 floats: 85 MB, and
// the convolutions' activations over them), so the kernel maps and zeroes
// fresh pages for each: half of a first-person-maze TRPO run's CPU time
// (docs/benchmarks.md, `vantage bench malloc`).

namespace vantage {

// What KeepFreedMemoryForReuse did.
enum class MallocSettings {
  kKeepFreedMemory,  // set below
  kEnvironment,      // glibc's own variables decide: left alone
  kNotGlibc,         // another C library: nothing to set
};

// Keeps freed memory in the process for the next allocation: no mmap for
// any block and no trimming below 2 GiB of free heap top. The cost is
// memory: the process stays at its peak, and malloc_trim (the learner
// server calls it every 10 s) gives back the main heap's free pages but no
// longer the tops of the threads' arenas. A process started with glibc's
// own settings in its environment (MALLOC_MMAP_MAX_, MALLOC_TRIM_THRESHOLD_,
// or a glibc.malloc.mmap_max or glibc.malloc.trim_threshold tunable in
// GLIBC_TUNABLES) keeps what they say: MALLOC_MMAP_MAX_=65536 keeps glibc's
// defaults. Safe with threads running (mallopt takes the main arena's
// lock); blocks mapped before the call stay mapped until freed.
MallocSettings KeepFreedMemoryForReuse();

// Whether an environment with these values (null: unset) decides glibc's
// mmap or trim settings itself.
bool EnvironmentSetsMalloc(const char* mmap_max, const char* trim_threshold,
                           const char* tunables);

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_MALLOC_SETTINGS_H_
