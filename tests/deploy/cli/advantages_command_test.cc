#include <algorithm>
#include <map>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// A valid request as key -> JSON value, so tests can drop or break one key.
std::map<std::string, std::string> ValidRequest() {
  return {{"gamma", "0.99"},
          {"lambda", "0.95"},
          {"ensemble", "[1, 16, 64, 2048]"},
          {"statistic", "\"maxabs\""},
          {"rho", "0.4"},
          {"seed", "3"},
          {"rewards", "[1, 0, 2]"},
          {"values", "[0.5, 0.2, 1]"},
          {"terminated", "[false, false, true]"},
          {"truncated", "[false, false, false]"},
          {"truncation_values", "[0, 0, 0]"},
          {"last_value", "0.7"}};
}

std::string ToJson(const std::map<std::string, std::string>& request) {
  return absl::StrCat("{",
                      absl::StrJoin(request, ", ",
                                    [](std::string* out, const auto& entry) {
                                      absl::StrAppend(out, "\"", entry.first,
                                                      "\": ", entry.second);
                                    }),
                      "}");
}

Outcome RunWith(const std::map<std::string, std::string>& request) {
  return RunVantage(absl::StrCat("advantages --input=",
                                 WriteTemp("request.json", ToJson(request))));
}

void ExpectBadInput(const Outcome& outcome, const std::string& message) {
  EXPECT_EQ(outcome.exit_code, 2) << outcome.err;
  EXPECT_THAT(outcome.err, HasSubstr(message));
  // Exactly one line.
  EXPECT_EQ(std::count(outcome.err.begin(), outcome.err.end(), '\n'), 1)
      << outcome.err;
  EXPECT_EQ(outcome.out, "");
}

TEST(AdvantagesCommandTest, GoldenOutput) {
  // By hand (gamma = lambda = 0.5): the episode t=0..1 terminates, t=2..3
  // is cut by the rollout's end with V(s_T) = 4.
  //   deltas: 1 + .5*1 - .5 = 1, 2 + 0 - 1 = 1, 4 + .5*2 - 0 = 5,
  //           8 + .5*4 - 2 = 8
  //   gae: [1 + .25*1, 1, 5 + .25*8, 8] = [1.25, 1, 7, 8]
  //   A^(2): [1 + .5*2 - .5, 1, 4 + .5*8 + .25*4, 8] = [1.5, 1, 9, 8]
  //   max(A^(1), A^(2)) = [1.5, 1, 9, 8]; returns = V + gae.
  // The mask of seed 8 is [1, 0, 0, 0]: mixed takes max at t = 0 only.
  const Outcome outcome = RunVantage(absl::StrCat(
      "advantages --input=", VANTAGE_TESTDATA, "/golden_request.json"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_EQ(outcome.out,
            ReadFile(absl::StrCat(VANTAGE_TESTDATA, "/golden_response.json")));
  EXPECT_THAT(outcome.out, HasSubstr("\"gae\":[1.25,1,7,8]"));
  EXPECT_THAT(outcome.out, HasSubstr("\"biased\":[1.5,1,9,8]"));
  EXPECT_THAT(outcome.out, HasSubstr("\"returns\":[1.75,2,7,10]"));
  EXPECT_THAT(outcome.out, HasSubstr("\"mixed\":[1.5,1,7,8]"));
}

TEST(AdvantagesCommandTest, ValidRequestSucceeds) {
  const Outcome outcome = RunWith(ValidRequest());
  EXPECT_EQ(outcome.exit_code, 0) << outcome.err;
  for (const char* key : {"gae", "biased", "mixed", "mask", "returns"}) {
    EXPECT_THAT(outcome.out, HasSubstr(absl::StrCat("\"", key, "\":")));
  }
}

TEST(AdvantagesCommandTest, ExampleRuns) {
  const Outcome outcome = RunVantage("advantages --example");
  EXPECT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("A^(16)"));
  EXPECT_THAT(outcome.out, HasSubstr("maxabs"));
  EXPECT_THAT(outcome.out, HasSubstr("trunc"));
}

TEST(AdvantagesCommandTest, EveryMissingKeyIsNamed) {
  for (const auto& [key, value] : ValidRequest()) {
    std::map<std::string, std::string> request = ValidRequest();
    request.erase(key);
    ExpectBadInput(RunWith(request), absl::StrCat("missing key '", key, "'"));
  }
}

TEST(AdvantagesCommandTest, WrongLengthsAreNamed) {
  for (const char* key :
       {"values", "terminated", "truncated", "truncation_values"}) {
    std::map<std::string, std::string> request = ValidRequest();
    request[key] =
        key == std::string("terminated") || key == std::string("truncated")
            ? "[false, false]"
            : "[1, 2, 3, 4]";
    ExpectBadInput(RunWith(request), absl::StrCat("'", key, "' has "));
  }
}

TEST(AdvantagesCommandTest, NonFiniteNumbersAreRefused) {
  std::map<std::string, std::string> request = ValidRequest();
  request["rewards"] = "[1, \"NaN\", 2]";
  ExpectBadInput(RunWith(request), "'rewards'[1] must be a finite number");
  request = ValidRequest();
  request["values"] = "[\"Infinity\", 0, 0]";
  ExpectBadInput(RunWith(request), "'values'[0] must be a finite number");
  request = ValidRequest();
  request["last_value"] = "\"-Infinity\"";
  ExpectBadInput(RunWith(request), "'last_value' must be a finite number");
  request = ValidRequest();
  request["gamma"] = "\"NaN\"";
  ExpectBadInput(RunWith(request), "'gamma' must be a finite number");
}

TEST(AdvantagesCommandTest, BadStatisticListsTheValidOnes) {
  std::map<std::string, std::string> request = ValidRequest();
  request["statistic"] = "\"median\"";
  ExpectBadInput(RunWith(request),
                 "unknown statistic 'median'; valid statistics: gae, max, "
                 "min, maxabs, order:D");
  request["statistic"] = "\"order:5\"";
  ExpectBadInput(RunWith(request), "order:5 needs a rank in 1..4");
}

TEST(AdvantagesCommandTest, OutOfRangeSettingsAreRefused) {
  std::map<std::string, std::string> request = ValidRequest();
  request["gamma"] = "1.5";
  ExpectBadInput(RunWith(request), "gamma must be in (0, 1]");
  request = ValidRequest();
  request["rho"] = "-0.1";
  ExpectBadInput(RunWith(request), "rho must be in [0, 1]");
  request = ValidRequest();
  request["ensemble"] = "[1, 0]";
  ExpectBadInput(RunWith(request), "positive step counts, got 0");
}

TEST(AdvantagesCommandTest, MalformedJsonAndWrongTypes) {
  ExpectBadInput(
      RunVantage(absl::StrCat("advantages --input=",
                              WriteTemp("broken.json", "{\"gamma\": "))),
      "invalid JSON input");
  std::map<std::string, std::string> request = ValidRequest();
  request["terminated"] = "[0, 1, 0]";
  ExpectBadInput(RunWith(request), "invalid JSON input");
  request = ValidRequest();
  request["colour"] = "\"blue\"";
  ExpectBadInput(RunWith(request), "invalid JSON input");
}

TEST(AdvantagesCommandTest, MissingFileAndFlag) {
  ExpectBadInput(RunVantage("advantages --input=/nonexistent/rollout.json"),
                 "cannot open --input file '/nonexistent/rollout.json'");
  ExpectBadInput(RunVantage("advantages"), "--input=FILE.json is required");
}

TEST(AdvantagesCommandTest, UnknownCommandListsTheValidOnes) {
  const Outcome outcome = RunVantage("frobnicate");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("unknown command 'frobnicate'"));
  EXPECT_THAT(outcome.err, HasSubstr("actor, advantages"));
}

}  // namespace
}  // namespace vantage
