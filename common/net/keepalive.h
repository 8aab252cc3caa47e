#ifndef VANTAGE_COMMON_NET_KEEPALIVE_H_
#define VANTAGE_COMMON_NET_KEEPALIVE_H_

// How an actor notices a link that drops its packets (a cut cable, a host
// gone without closing its connections): TCP alone keeps such a connection
// open and backs off its retransmissions to a minute and more, so an actor
// whose link came back could wait that long to hear that the learner had
// expired it. The actor pings the learner every kKeepaliveIntervalMs and
// closes the connection when a ping goes unanswered for
// kKeepaliveTimeoutMs, then reconnects as after any failure; the learner
// accepts pings that often (gRPC's servers refuse pings closer than five
// minutes apart by default, and close the connection of a client that
// keeps sending them).

namespace vantage {

inline constexpr int kKeepaliveIntervalMs = 10000;
inline constexpr int kKeepaliveTimeoutMs = 10000;
// What the learner allows: half the actors' interval, for timer slack.
inline constexpr int kMinPingIntervalMs = kKeepaliveIntervalMs / 2;
// The longest an actor's channel waits between attempts to reconnect
// (gRPC's default grows to 120 s).
inline constexpr int kMaxReconnectBackoffMs = 5000;

}  // namespace vantage

#endif  // VANTAGE_COMMON_NET_KEEPALIVE_H_
