// serve --trusted_proxies (server/auth/trusted_proxies.h): which peers may name the caller.
#include "server/auth/trusted_proxies.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/auth/authenticator.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;

TEST(TrustedProxiesTest, ATrustedProxyNamesTheClientsConnection) {
  const absl::StatusOr<TrustedProxies> proxies =
      TrustedProxies::Parse(" 127.0.0.1, 10.0.0.0/8 ,fd00::/8");
  ASSERT_TRUE(proxies.ok()) << proxies.status();
  EXPECT_EQ(proxies->CallerName("ipv4:127.0.0.1:4000", "192.0.2.7:51234"),
            "ipv4:192.0.2.7:51234");
  EXPECT_EQ(proxies->CallerName("ipv4:10.1.2.3:4000", "2001:db8::5:443"),
            "ipv6:[2001:db8::5]:443");
  EXPECT_EQ(proxies->CallerName("ipv4:10.1.2.3:4000", "[2001:db8::5]:443"),
            "ipv6:[2001:db8::5]:443");
  EXPECT_EQ(proxies->CallerName("ipv6:[fd12::1]:4000", "192.0.2.7:1"), "ipv4:192.0.2.7:1");
  // As gRPC 1.51 writes an IPv6 peer: a URI, its brackets escaped.
  EXPECT_EQ(proxies->CallerName("ipv6:%5Bfd12::1%5D:4000", "192.0.2.7:1"), "ipv4:192.0.2.7:1");
  EXPECT_EQ(proxies->CallerName("ipv6:%5Bfe80::1%5D:4000", "192.0.2.7:1"),
            "ipv6:%5Bfe80::1%5D:4000");  // not in fd00::/8
  // An IPv4 proxy on a dual-stack listener.
  EXPECT_EQ(proxies->CallerName("ipv6:[::ffff:127.0.0.1]:4000", "192.0.2.7:1"),
            "ipv4:192.0.2.7:1");
}

TEST(TrustedProxiesTest, OtherPeersAndBadNamesKeepThePeer) {
  const absl::StatusOr<TrustedProxies> proxies = TrustedProxies::Parse("127.0.0.1,10.0.0.0/8");
  ASSERT_TRUE(proxies.ok()) << proxies.status();
  // Not trusted: a client cannot choose its principal.
  EXPECT_EQ(proxies->CallerName("ipv4:127.0.0.2:4000", "192.0.2.7:1"), "ipv4:127.0.0.2:4000");
  EXPECT_EQ(proxies->CallerName("ipv4:11.0.0.1:4000", "192.0.2.7:1"), "ipv4:11.0.0.1:4000");
  EXPECT_EQ(proxies->CallerName("unix:/tmp/s", "192.0.2.7:1"), "unix:/tmp/s");
  // Trusted, but no or no valid name.
  EXPECT_EQ(proxies->CallerName("ipv4:127.0.0.1:4000", std::nullopt), "ipv4:127.0.0.1:4000");
  for (const char* bad : {"", "192.0.2.7", "192.0.2.7:70000", "alice:1", "[::1:5", "1.2.3.4:x"}) {
    EXPECT_EQ(proxies->CallerName("ipv4:127.0.0.1:4000", bad), "ipv4:127.0.0.1:4000") << bad;
  }
  // None trusted (the default): always the peer.
  EXPECT_EQ(TrustedProxies().CallerName("ipv4:127.0.0.1:4000", "192.0.2.7:1"),
            "ipv4:127.0.0.1:4000");
}

TEST(TrustedProxiesTest, BadEntriesAreNamed) {
  for (const char* bad :
       {"localhost", "10.0.0.0/33", "::/129", "10.0.0.0/x", "10.0.0.0/-1", "1.2.3.4,,"}) {
    const absl::StatusOr<TrustedProxies> proxies = TrustedProxies::Parse(bad);
    EXPECT_EQ(proxies.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_THAT(proxies.status().message(), HasSubstr("trusted_proxies: '")) << bad;
  }
  EXPECT_TRUE(TrustedProxies::Parse("").value().empty());
}

}  // namespace
}  // namespace splinegrid::server
