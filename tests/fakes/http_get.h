#ifndef VANTAGE_TESTS_FAKES_HTTP_GET_H_
#define VANTAGE_TESTS_FAKES_HTTP_GET_H_

// A minimal HTTP/1.0 client over a POSIX socket, enough to scrape a
// metrics endpoint on loopback without a curl dependency.

#include <string>

#include "absl/status/statusor.h"

namespace vantage {

// GET http://127.0.0.1:<port><path> with `headers` ("Name: value\r\n"
// lines) added; the body of a 200 answer, otherwise an error carrying the
// status line. Gives up after a few seconds.
absl::StatusOr<std::string> HttpGet(int port, const std::string& path,
                                    const std::string& headers = "");

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_HTTP_GET_H_
