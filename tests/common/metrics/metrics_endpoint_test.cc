#include "common/metrics/metrics_endpoint.h"

#include <memory>
#include <string>

#include "absl/strings/escaping.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "prometheus/counter.h"
#include "prometheus/exposer.h"
#include "prometheus/registry.h"
#include "tests/fakes/http_get.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

TEST(MetricsEndpointTest, APortAloneBindsLoopback) {
  EXPECT_EQ(ResolveMetricsAddress("9100"), "127.0.0.1:9100");
  EXPECT_EQ(ResolveMetricsAddress(":0"), "127.0.0.1:0");
  EXPECT_EQ(ResolveMetricsAddress("0.0.0.0:9100"), "0.0.0.0:9100");
  EXPECT_EQ(ResolveMetricsAddress(""), "");
  EXPECT_TRUE(IsLoopbackAddress("127.0.0.1:9100"));
  EXPECT_TRUE(IsLoopbackAddress("localhost:1"));
  EXPECT_TRUE(IsLoopbackAddress("[::1]:1"));
  EXPECT_FALSE(IsLoopbackAddress("0.0.0.0:9100"));
  EXPECT_FALSE(IsLoopbackAddress("10.1.2.3:9100"));
}

class MetricsEndpointServeTest : public ::testing::Test {
 protected:
  MetricsEndpointServeTest()
      : registry_(std::make_shared<prometheus::Registry>()) {
    prometheus::BuildCounter()
        .Name("endpoint_test_total")
        .Help("A counter.")
        .Register(*registry_)
        .Add({})
        .Increment(3);
  }
  std::shared_ptr<prometheus::Registry> registry_;
};

TEST_F(MetricsEndpointServeTest, LoopbackNeedsNoCredentials) {
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint({"0", "secret"}, registry_, "test");
  ASSERT_TRUE(exposer.ok()) << exposer.status();
  absl::StatusOr<std::string> body =
      HttpGet(MetricsPort(**exposer), "/metrics");
  ASSERT_TRUE(body.ok()) << body.status();
  EXPECT_THAT(*body, HasSubstr("endpoint_test_total 3"));
}

TEST_F(MetricsEndpointServeTest, BeyondLoopbackTheTokenIsRequired) {
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint({"0.0.0.0:0", "secret"}, registry_, "test");
  ASSERT_TRUE(exposer.ok()) << exposer.status();
  const int port = MetricsPort(**exposer);
  absl::StatusOr<std::string> refused = HttpGet(port, "/metrics");
  EXPECT_FALSE(refused.ok());
  EXPECT_THAT(refused.status().message(), HasSubstr("401"));
  absl::StatusOr<std::string> wrong = HttpGet(
      port, "/metrics",
      "Authorization: Basic " + absl::Base64Escape("vantage:guess") + "\r\n");
  EXPECT_FALSE(wrong.ok());
  absl::StatusOr<std::string> body = HttpGet(
      port, "/metrics",
      "Authorization: Basic " + absl::Base64Escape("vantage:secret") + "\r\n");
  ASSERT_TRUE(body.ok()) << body.status();
  EXPECT_THAT(*body, HasSubstr("endpoint_test_total 3"));
}

TEST_F(MetricsEndpointServeTest, AnAddressThatCannotBeBoundIsNamed) {
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint(MetricsEndpointOptions{"not-an-address:x", ""},
                           registry_, "test");
  EXPECT_TRUE(absl::IsUnavailable(exposer.status())) << exposer.status();
  EXPECT_THAT(exposer.status().message(),
              HasSubstr("cannot serve test metrics on \"not-an-address:x\""));
}

}  // namespace
}  // namespace vantage
