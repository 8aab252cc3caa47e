#include "deploy/observe/scrape_targets.h"

#include <unistd.h>

#include <string>

#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

TEST(ScrapeTargetsTest, AFileSdListOfOneGroupPerTarget) {
  const std::string path = TempPath("targets.json");
  ASSERT_TRUE(
      WriteScrapeTargets(
          path, {{"127.0.0.1:9100", {{"role", "learner"}, {"run", "a \"b\""}}},
                 {"127.0.0.1:9101", {{"role", "actor"}, {"actor", "0"}}}})
          .ok());
  google::protobuf::ListValue list;
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(ReadFile(path), &list).ok())
      << ReadFile(path);
  ASSERT_EQ(list.values_size(), 2);
  const auto& first = list.values(0).struct_value().fields();
  EXPECT_EQ(first.at("targets").list_value().values(0).string_value(),
            "127.0.0.1:9100");
  // Label values are escaped as JSON strings.
  EXPECT_EQ(first.at("labels").struct_value().fields().at("run").string_value(),
            "a \"b\"");
  EXPECT_EQ(list.values(1)
                .struct_value()
                .fields()
                .at("labels")
                .struct_value()
                .fields()
                .at("actor")
                .string_value(),
            "0");
  // Nothing to scrape is an empty list, which Prometheus accepts.
  ASSERT_TRUE(WriteScrapeTargets(path, {}).ok());
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(ReadFile(path), &list).ok());
  EXPECT_EQ(list.values_size(), 0);
  EXPECT_FALSE(WriteScrapeTargets("/nonexistent/dir/targets.json", {}).ok());
}

TEST(ScrapeTargetsTest, AWildcardBindIsScrapedThroughTheHostName) {
  char name[256] = {};
  ASSERT_EQ(gethostname(name, sizeof(name) - 1), 0);
  EXPECT_EQ(ScrapeAddress("0.0.0.0", 9100), std::string(name) + ":9100");
  EXPECT_EQ(ScrapeAddress("[::]", 9100), std::string(name) + ":9100");
  EXPECT_EQ(ScrapeAddress("127.0.0.1", 9100), "127.0.0.1:9100");
  EXPECT_EQ(ScrapeAddress("[::1]", 9100), "[::1]:9100");
  EXPECT_EQ(ScrapeAddress("node7", 9100), "node7:9100");
}

}  // namespace
}  // namespace vantage
