#ifndef VANTAGE_COMMON_NET_GRPC_SECURITY_H_
#define VANTAGE_COMMON_NET_GRPC_SECURITY_H_

// SecurityOptions as gRPC credentials and per-call auth tokens, for both
// ends of the actor-learner connection.

#include <grpcpp/grpcpp.h>

#include <memory>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/net/security_options.h"

namespace vantage {

// TLS or insecure credentials as `options` say; unreadable PEM files are
// errors naming them. The token is not part of them (see CheckAuthToken,
// AddAuthToken).
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const SecurityOptions& options);
absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>>
MakeChannelCredentials(const SecurityOptions& options);

// Adds the token (if any) to one call's metadata.
void AddAuthToken(const SecurityOptions& options, grpc::ClientContext& context);

// OK if `token` is empty or the call carries it; UNAUTHENTICATED otherwise.
grpc::Status CheckAuthToken(const grpc::ServerContext& context,
                            absl::string_view token);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NET_GRPC_SECURITY_H_
