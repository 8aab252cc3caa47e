#include "common/util/self_process.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr char kDeleteSelf[] = "VANTAGE_SPAWN_SELF_TEST_DELETE";

// Run by the test below in a copy of this binary: removes the copy's file,
// as a rebuild does to a running binary, then spawns itself.
TEST(SpawnSelfTest, SpawnsItselfAfterItsFileIsGone) {
  if (std::getenv(kDeleteSelf) == nullptr) GTEST_SKIP() << "run by the next";
  std::error_code error;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", error);
  ASSERT_FALSE(error);
  ASSERT_TRUE(std::filesystem::remove(self, error)) << self;
  unsetenv(kDeleteSelf);
  absl::StatusOr<pid_t> child =
      SpawnSelf({"--gtest_filter=SpawnSelfTest.DoesNothing"});
  ASSERT_TRUE(child.ok()) << child.status();
  int status = 0;
  ASSERT_EQ(waitpid(*child, &status, 0), *child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);  // 127: the exec failed
}

TEST(SpawnSelfTest, DoesNothing) {}

TEST(SpawnSelfTest, ARebuiltOrRemovedBinaryStillSpawnsWhatItRuns) {
  std::error_code error;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", error);
  ASSERT_FALSE(error);
  const std::filesystem::path copy =
      std::filesystem::temp_directory_path() /
      absl::StrCat("vantage-spawn-self-test-", getpid());
  std::filesystem::copy_file(
      self, copy, std::filesystem::copy_options::overwrite_existing, error);
  ASSERT_FALSE(error) << error.message();
  const std::string command = absl::StrCat(
      kDeleteSelf, "=1 ", copy.string(),
      " --gtest_filter=SpawnSelfTest.SpawnsItselfAfterItsFileIsGone"
      " >/dev/null 2>&1");
  const int status = std::system(command.c_str());
  std::filesystem::remove(copy, error);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_FALSE(std::filesystem::exists(copy));
}

}  // namespace
}  // namespace vantage
