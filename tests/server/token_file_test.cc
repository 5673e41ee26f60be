// The tokens file parser, the authenticator's table and reload, the delete rule and the
// transport checks (server/auth/), without a server.
#include "server/auth/token_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/auth/authenticator.h"
#include "server/auth/caller.h"
#include "server/auth/transport.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kAliceToken[] = "alice-secret-0001";
constexpr char kBobToken[] = "bob-secret-0002";

MATCHER_P2(StatusIs, code, fragment, "") {
  const absl::Status status = arg;
  *result_listener << "status " << status;
  return status.code() == code && status.message().find(fragment) != std::string::npos;
}

// A file in a fresh temporary directory, removed with the test.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    path_ = std::filesystem::temp_directory_path() /
            absl::StrCat("splinegrid-tokens-", getpid(), "-", counter_++);
    Write(text);
  }
  ~TempFile() { std::filesystem::remove(path_); }
  void Write(const std::string& text) const { std::ofstream(path_) << text; }
  std::string path() const { return path_.string(); }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

TEST(TokenFileTest, ParsesLinesCommentsAndBlanks) {
  const std::string text =
      absl::StrCat("# tokens of the test\n\n  ", kAliceToken, "  alice\twrite   # a writer\n",
                   kBobToken, " bob read\r\nadmin-secret-03 root admin\n");
  const absl::StatusOr<std::vector<TokenEntry>> entries = ParseTokenFile(text, "t");
  ASSERT_TRUE(entries.ok()) << entries.status();
  ASSERT_EQ(entries->size(), 3u);
  EXPECT_EQ((*entries)[0].token, kAliceToken);
  EXPECT_EQ((*entries)[0].caller.principal, "alice");
  EXPECT_EQ((*entries)[0].caller.role, Role::kWrite);
  EXPECT_EQ((*entries)[1].caller.role, Role::kRead);
  EXPECT_EQ((*entries)[2].caller.principal, "root");
  EXPECT_EQ((*entries)[2].caller.role, Role::kAdmin);
}

TEST(TokenFileTest, OnlyCommentsIsAnEmptyTable) {
  const absl::StatusOr<std::vector<TokenEntry>> entries = ParseTokenFile("# none\n\n", "t");
  ASSERT_TRUE(entries.ok());
  EXPECT_TRUE(entries->empty());
}

TEST(TokenFileTest, ErrorsNameTheLineAndNeverTheToken) {
  const struct {
    std::string line;
    std::string fragment;
  } cases[] = {
      {absl::StrCat(kAliceToken, " alice superuser"), "is not read, write or admin"},
      {absl::StrCat(kAliceToken, " alice"), "3 fields), found 2"},
      {absl::StrCat(kAliceToken, " alice write extra"), "found 4"},
      {"short alice read", "must be 8-512"},
      // In the wrong order the third field is the token: never quoted.
      {absl::StrCat("ops-admin write ", kAliceToken), "is not read, write or admin"},
  };
  for (const auto& c : cases) {
    const std::string text = absl::StrCat("# header\n", kBobToken, " bob read\n", c.line, "\n");
    const absl::Status status = ParseTokenFile(text, "/etc/sg/tokens").status();
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, "/etc/sg/tokens:3: "))
        << c.line;
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.fragment));
    EXPECT_THAT(std::string(status.message()), Not(HasSubstr(kAliceToken)));
    EXPECT_THAT(std::string(status.message()), Not(HasSubstr("short")));
  }
}

TEST(TokenFileTest, RefusesARepeatedToken) {
  const std::string text = absl::StrCat(kAliceToken, " alice read\n", kAliceToken, " eve admin\n");
  const absl::Status status = ParseTokenFile(text, "f").status();
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, "f:2: the token is repeated"));
  EXPECT_THAT(std::string(status.message()), Not(HasSubstr(kAliceToken)));
}

TEST(TokenFileTest, AMissingFileIsNotFoundNamingThePath) {
  EXPECT_THAT(ReadTokenFile("/nonexistent/tokens").status(),
              StatusIs(absl::StatusCode::kNotFound, "'/nonexistent/tokens'"));
}

TEST(ConstantTimeEqualsTest, ComparesWholeStrings) {
  EXPECT_TRUE(ConstantTimeEquals("abcdefgh", "abcdefgh"));
  EXPECT_FALSE(ConstantTimeEquals("abcdefgh", "abcdefgi"));
  EXPECT_FALSE(ConstantTimeEquals("abcdefg", "abcdefgh"));
  EXPECT_FALSE(ConstantTimeEquals("abcdefghi", "abcdefgh"));
  EXPECT_FALSE(ConstantTimeEquals("", "abcdefgh"));
  EXPECT_TRUE(ConstantTimeEquals("", ""));
}

TEST(AuthenticatorTest, WithoutTokensEveryCallerIsAnAdminNamedByItsPeer) {
  Authenticator authenticator;
  EXPECT_EQ(authenticator.num_tokens(), 0);
  const absl::StatusOr<Caller> caller = authenticator.Authenticate(std::nullopt, "ipv4:1.2.3.4:5");
  ASSERT_TRUE(caller.ok());
  EXPECT_EQ(caller->principal, "ipv4:1.2.3.4:5");
  EXPECT_EQ(caller->role, Role::kAdmin);
  EXPECT_EQ(caller->owner(), "");  // grids made without tokens have no owner
  EXPECT_THAT(authenticator.Reload().status(), StatusIs(absl::StatusCode::kFailedPrecondition, ""));
}

TEST(AuthenticatorTest, TokensNameThePrincipalAndRole) {
  const TempFile file(absl::StrCat(kAliceToken, " alice write\n", kBobToken, " bob read\n"));
  Authenticator authenticator;
  ASSERT_EQ(authenticator.LoadTokens(file.path()).value(), 2);
  const std::string bearer = absl::StrCat("Bearer ", kAliceToken);
  const absl::StatusOr<Caller> alice = authenticator.Authenticate(bearer, "peer");
  ASSERT_TRUE(alice.ok()) << alice.status();
  EXPECT_EQ(alice->principal, "alice");
  EXPECT_EQ(alice->role, Role::kWrite);
  EXPECT_EQ(alice->owner(), "alice");
  // The scheme is case-insensitive (RFC 7235).
  EXPECT_EQ(authenticator.Authenticate(absl::StrCat("bearer ", kBobToken), "p")->principal, "bob");

  EXPECT_THAT(authenticator.Authenticate(std::nullopt, "p").status(),
              StatusIs(absl::StatusCode::kUnauthenticated, "needs a token"));
  EXPECT_THAT(authenticator.Authenticate(std::string("Basic ") + kAliceToken, "p").status(),
              StatusIs(absl::StatusCode::kUnauthenticated, "not 'Bearer TOKEN'"));
  const absl::Status unknown = authenticator.Authenticate("Bearer alice-secret-0009", "p").status();
  EXPECT_THAT(unknown, StatusIs(absl::StatusCode::kUnauthenticated, "not known"));
  EXPECT_THAT(std::string(unknown.message()), Not(HasSubstr("alice-secret")));
  // A prefix of a token is not the token.
  EXPECT_THAT(authenticator.Authenticate("Bearer alice-secret-000", "p").status(),
              StatusIs(absl::StatusCode::kUnauthenticated, ""));
}

TEST(AuthenticatorTest, ReloadSwapsTheTableAndABadFileKeepsTheOldOne) {
  const TempFile file(absl::StrCat(kAliceToken, " alice read\n"));
  Authenticator authenticator;
  ASSERT_TRUE(authenticator.LoadTokens(file.path()).ok());
  const std::string alice = absl::StrCat("Bearer ", kAliceToken);
  EXPECT_EQ(authenticator.Authenticate(alice, "p")->role, Role::kRead);

  file.Write(absl::StrCat(kAliceToken, " alice admin\n", kBobToken, " bob write\n"));
  EXPECT_EQ(authenticator.Reload().value(), 2);
  EXPECT_EQ(authenticator.Authenticate(alice, "p")->role, Role::kAdmin);
  EXPECT_EQ(authenticator.Authenticate(absl::StrCat("Bearer ", kBobToken), "p")->role,
            Role::kWrite);

  file.Write(absl::StrCat(kAliceToken, " alice root\n"));
  EXPECT_THAT(authenticator.Reload().status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ":1: the third field (the role)"));
  EXPECT_EQ(authenticator.num_tokens(), 2);
  EXPECT_EQ(authenticator.Authenticate(alice, "p")->role, Role::kAdmin);

  file.Write("# everyone removed\n");
  EXPECT_THAT(authenticator.Reload().status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "has no tokens"));
  EXPECT_EQ(authenticator.num_tokens(), 2);
}

TEST(AuthenticatorTest, AFileWithoutTokensIsRefusedAtStart) {
  const TempFile file("# nothing yet\n");
  Authenticator authenticator;
  EXPECT_THAT(authenticator.LoadTokens(file.path()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "has no tokens"));
  EXPECT_EQ(authenticator.num_tokens(), 0);
}

TEST(MayChangeGridTest, AdminAnyWriterOwnReaderNone) {
  const Caller admin{"root", Role::kAdmin, true};
  const Caller alice{"alice", Role::kWrite, true};
  const Caller reader{"carol", Role::kRead, true};
  EXPECT_TRUE(MayChangeGrid(admin, "alice", "grids/a", "deleting").ok());
  EXPECT_TRUE(MayChangeGrid(admin, "", "grids/a", "deleting").ok());
  EXPECT_TRUE(MayChangeGrid(alice, "alice", "grids/a", "deleting").ok());
  EXPECT_THAT(MayChangeGrid(alice, "bob", "grids/a", "deleting"),
              StatusIs(absl::StatusCode::kPermissionDenied,
                       "grids/a belongs to 'bob': deleting it needs the role admin"));
  EXPECT_THAT(MayChangeGrid(alice, "", "grids/a", "deleting"),
              StatusIs(absl::StatusCode::kPermissionDenied, "has no owner: deleting it needs"));
  EXPECT_THAT(MayChangeGrid(reader, "carol", "grids/a", "deleting"),
              StatusIs(absl::StatusCode::kPermissionDenied, "the caller has read"));
  // Without tokens the principal is a peer address, never an owner.
  const Caller peer{"alice", Role::kWrite, false};
  EXPECT_FALSE(MayChangeGrid(peer, "alice", "grids/a", "deleting").ok());
}

TEST(TransportTest, LoopbackAddresses) {
  for (const char* address : {"localhost:50051", "127.0.0.1:1", "127.3.2.1:9", "[::1]:50051",
                              "unix:/tmp/sg.sock", "ipv4:127.0.0.1:5", "::1"}) {
    EXPECT_TRUE(IsLoopbackAddress(address)) << address;
  }
  for (const char* address : {"0.0.0.0:50051", "[::]:50051", "10.0.0.1:1", "example.com:443",
                              "192.168.1.1:80", ":50051", "[::ffff:10.0.0.1]:1"}) {
    EXPECT_FALSE(IsLoopbackAddress(address)) << address;
  }
}

TEST(TransportTest, PlaintextOnTheNetworkNeedsInsecure) {
  ServerOptions options;
  options.address = "0.0.0.0:0";
  EXPECT_THAT(MakeServerCredentials(options).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "--insecure"));
  options.insecure = true;
  EXPECT_TRUE(MakeServerCredentials(options).ok());
  options.insecure = false;
  options.address = "127.0.0.1:0";
  EXPECT_TRUE(MakeServerCredentials(options).ok());
  EXPECT_EQ(TransportName(options), "plaintext");
}

TEST(TransportTest, TlsOptionsAreCheckedAndFilesNamed) {
  ServerOptions options;
  options.address = "0.0.0.0:0";
  options.tls_cert_file = "/nonexistent/cert.pem";
  EXPECT_THAT(MakeServerCredentials(options).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "--tls_key"));
  options.tls_key_file = "/nonexistent/key.pem";
  EXPECT_THAT(MakeServerCredentials(options).status(),
              StatusIs(absl::StatusCode::kNotFound, "--tls_cert: cannot read '/nonexistent/cert"));
  const TempFile not_pem("hello\n");
  options.tls_cert_file = not_pem.path();
  EXPECT_THAT(MakeServerCredentials(options).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "is not a PEM file"));
  ServerOptions client_ca_only;
  client_ca_only.tls_client_ca_file = not_pem.path();
  EXPECT_THAT(MakeServerCredentials(client_ca_only).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "--tls_client_ca"));
  EXPECT_EQ(TransportName(options), "TLS");
  options.tls_client_ca_file = "x";
  EXPECT_EQ(TransportName(options), "mTLS");
}

}  // namespace
}  // namespace splinegrid::server
