// Tokens and roles through the service (in process): UNAUTHENTICATED without a known token,
// PERMISSION_DENIED below the call's role, grid ownership for DeleteGrid (kept by the durable
// store), health open to everyone, reloads taking effect, and tokens never in error messages.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "absl/strings/str_cat.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kGrid[] = "grids/n0012_113-33.p2dfmt";

// Principal and role of each test token.
const std::map<std::string, std::string>& Tokens() {
  static const auto* tokens = new std::map<std::string, std::string>{
      {"read-token-r1", "carol read"},
      {"write-token-a1", "alice write"},
      {"write-token-b1", "bob write"},
      {"admin-token-z1", "root admin"},
  };
  return *tokens;
}

class AuthTest : public ServiceTest {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / absl::StrCat("splinegrid-auth-", getpid());
    std::filesystem::create_directories(dir_);
    WriteTokens(Tokens());
    options_.tokens_file = (dir_ / "tokens").string();
    StartServer();
    grid_bytes_ = ReadFileToString(SharedDataPath(kGrid)).value();
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  void WriteTokens(const std::map<std::string, std::string>& tokens) {
    std::ofstream out(dir_ / "tokens");
    out << "# test tokens\n";
    for (const auto& [token, who] : tokens) out << token << " " << who << "\n";
  }

  // A client of the in-process server that sends `token` (empty: none).
  std::unique_ptr<client::Client> As(const std::string& token) {
    client::ClientOptions options;
    options.timeout = absl::Seconds(60);
    options.retry.max_attempts = 1;
    options.token = token;
    return std::make_unique<client::Client>(server_->InProcessChannel(), options);
  }

  absl::StatusOr<v1::Grid> Import(client::Client& client, const std::string& id) {
    return client.ImportPlot3d(grid_bytes_, id, kGrid, false);
  }

  // Expects `status` to have `code` and not to contain any token.
  static void ExpectCode(const absl::Status& status, absl::StatusCode code) {
    EXPECT_EQ(status.code(), code) << status;
    for (const auto& [token, who] : Tokens()) {
      EXPECT_THAT(std::string(status.message()), Not(HasSubstr(token)));
    }
  }

  std::filesystem::path dir_;
  std::string grid_bytes_;
};

TEST_F(AuthTest, WithoutAKnownTokenEveryCallIsUnauthenticatedButHealthIsOpen) {
  for (const std::string token : {"", "not-a-known-token"}) {
    auto client = As(token);
    ExpectCode(client->List().status(), absl::StatusCode::kUnauthenticated);
    ExpectCode(client->Get("grids/any").status(), absl::StatusCode::kUnauthenticated);
    ExpectCode(Import(*client, "x").status(), absl::StatusCode::kUnauthenticated);
    ExpectCode(client->Delete("grids/any"), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(client->Health("").value(), "SERVING");
    EXPECT_EQ(client->Health(server::kServiceName).value(), "SERVING");
  }
}

// A refused call's log line names the connection it came from (no principal is known), so
// that an operator can tell where unknown tokens come from; the token is not in it.
TEST_F(AuthTest, ARefusedTokensLogLineNamesItsConnection) {
  server_.reset();
  options_.log_calls = true;
  options_.address = "127.0.0.1:0";
  StartServer();
  client::ClientOptions options;
  options.retry.max_attempts = 1;
  options.token = "not-a-known-token";
  client::Client remote(grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_->port()),
                                            grpc::InsecureChannelCredentials()),
                        options);
  ::testing::internal::CaptureStderr();
  ExpectCode(remote.List().status(), absl::StatusCode::kUnauthenticated);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(log, HasSubstr(" UNAUTHENTICATED "));
  EXPECT_THAT(log, HasSubstr(" by ipv4:127.0.0.1:"));
  EXPECT_THAT(log, HasSubstr(": the token is not known to this server"));
  EXPECT_THAT(log, Not(HasSubstr("not-a-known-token")));
}

// Every role (and none) against one call of each class: read (GetGrid), write (ImportGrid),
// changing (FitGrid) and deleting the caller's own grid, and another principal's (bob's).
TEST_F(AuthTest, RoleMatrix) {
  using Code = absl::StatusCode;
  const struct {
    std::string token;
    Code read, write, own, other;
  } rows[] = {
      {"", Code::kUnauthenticated, Code::kUnauthenticated, Code::kUnauthenticated,
       Code::kUnauthenticated},
      {"unknown-token-9", Code::kUnauthenticated, Code::kUnauthenticated, Code::kUnauthenticated,
       Code::kUnauthenticated},
      {"read-token-r1", Code::kOk, Code::kPermissionDenied, Code::kPermissionDenied,
       Code::kPermissionDenied},
      {"write-token-a1", Code::kOk, Code::kOk, Code::kOk, Code::kPermissionDenied},
      {"admin-token-z1", Code::kOk, Code::kOk, Code::kOk, Code::kOk},
  };
  auto bob = As("write-token-b1");
  v1::FitSpec spec;
  spec.set_allow_folds(true);  // these counts fold the C-grid at levels 1-2; roles are tested
  spec.mutable_control_counts()->set_i(12);
  spec.mutable_control_counts()->set_j(8);
  for (const auto& row : rows) {
    SCOPED_TRACE(row.token.empty()           ? "no token"
                 : Tokens().count(row.token) ? Tokens().at(row.token)
                                             : "unknown token");
    ASSERT_TRUE(Import(*bob, "bobs").ok());
    auto client = As(row.token);
    ExpectCode(client->Get("bobs").status(), row.read);
    ExpectCode(Import(*client, "mine").status(), row.write);
    if (row.write != Code::kOk) {
      // Nothing of its own to change or delete: a grid that does not belong to it.
      ExpectCode(client->Fit("bobs", spec).status(), row.own);
      ExpectCode(client->Delete("bobs"), row.own);
    } else {
      ExpectCode(client->Fit("mine", spec).status(), row.own);
      ExpectCode(client->Delete("mine"), row.own);
    }
    ExpectCode(client->Fit("bobs", spec).status(), row.other);
    ExpectCode(client->Delete("bobs"), row.other);
    if (row.other != Code::kOk) {
      ASSERT_TRUE(bob->Delete("bobs").ok());
    }
  }
}

TEST_F(AuthTest, EachRoleMayDoItsClassOfCalls) {
  auto reader = As("read-token-r1");
  auto alice = As("write-token-a1");
  auto admin = As("admin-token-z1");
  // write: import and fit; the grid belongs to its creator.
  const absl::StatusOr<v1::Grid> imported = Import(*alice, "by-alice");
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_EQ(imported->owner(), "alice");
  v1::FitSpec spec;
  spec.set_allow_folds(true);  // these counts fold the C-grid at levels 1-2; roles are tested
  spec.mutable_control_counts()->set_i(12);
  spec.mutable_control_counts()->set_j(8);
  EXPECT_TRUE(alice->Fit("by-alice", spec).ok());
  // read: get, list, evaluate-class calls; not import, fit or delete.
  EXPECT_EQ(reader->Get("by-alice").value().owner(), "alice");
  EXPECT_EQ(reader->List().value().size(), 1u);
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name("by-alice");
  evaluate.set_refinement_level(0);
  EXPECT_TRUE(reader->Evaluate(evaluate).ok());
  ExpectCode(Import(*reader, "by-carol").status(), absl::StatusCode::kPermissionDenied);
  ExpectCode(reader->Fit("by-alice", spec).status(), absl::StatusCode::kPermissionDenied);
  ExpectCode(reader->Delete("by-alice"), absl::StatusCode::kPermissionDenied);
  EXPECT_THAT(reader->Fit("by-alice", spec).status().message(),
              HasSubstr("needs the role write; the caller has read"));
  // GenerateGrid is a write call too, and makes its caller the owner.
  v1::GenerateGridRequest generate;
  generate.set_grid_id("generated");
  generate.set_wall_points(65);
  generate.set_layers(16);
  generate.set_first_height(1e-3);
  generate.set_distance(10.0);
  generate.set_airfoil_file(ReadFileToString(SharedDataPath("airfoils/naca0012.dat")).value());
  ExpectCode(reader->Generate(generate).status(), absl::StatusCode::kPermissionDenied);
  const absl::StatusOr<v1::GenerateGridResponse> generated = alice->Generate(generate);
  ASSERT_TRUE(generated.ok()) << generated.status();
  EXPECT_EQ(generated->grid().owner(), "alice");
  // admin: everything.
  EXPECT_TRUE(Import(*admin, "by-root").ok());
  EXPECT_TRUE(admin->Fit("by-root", spec).ok());
  EXPECT_TRUE(admin->Get("by-alice").ok());
}

TEST_F(AuthTest, AWriterDeletesOnlyItsOwnGridsAndAnAdminAny) {
  auto alice = As("write-token-a1");
  auto bob = As("write-token-b1");
  auto admin = As("admin-token-z1");
  ASSERT_TRUE(Import(*alice, "alice-1").ok());
  ASSERT_TRUE(Import(*alice, "alice-2").ok());
  ASSERT_TRUE(Import(*bob, "bob-1").ok());

  const absl::Status denied = bob->Delete("alice-1");
  ExpectCode(denied, absl::StatusCode::kPermissionDenied);
  EXPECT_THAT(denied.message(), HasSubstr("belongs to 'alice'"));
  EXPECT_TRUE(alice->Get("alice-1").ok());  // still there

  EXPECT_TRUE(alice->Delete("alice-1").ok());  // own grid
  EXPECT_EQ(alice->Get("alice-1").status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(admin->Delete("alice-2").ok());  // another principal's grid
  EXPECT_TRUE(admin->Delete("bob-1").ok());
  EXPECT_TRUE(admin->List().value().empty());
}

// A writer fits, fairs and deforms only its own grids, as it deletes only those; an admin any.
// (Only DeleteGrid checked the owner: a writer could deform another principal's grid.)
TEST_F(AuthTest, AWriterChangesOnlyItsOwnGridsAndAnAdminAny) {
  auto alice = As("write-token-a1");
  auto bob = As("write-token-b1");
  auto admin = As("admin-token-z1");
  ASSERT_TRUE(Import(*alice, "alices").ok());
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();  // the defaults by kind: no fold, so deforms are checked
  ASSERT_TRUE(alice->Fit("alices", spec).ok());
  v1::DeformGridRequest deform;
  deform.set_name("alices");
  for (double d : {1e-4, 0.0}) deform.mutable_rigid()->add_translation(d);

  const absl::Status fit = bob->Fit("alices", spec).status();
  ExpectCode(fit, absl::StatusCode::kPermissionDenied);
  EXPECT_THAT(fit.message(), HasSubstr("grids/alices belongs to 'alice': fitting it needs the "
                                       "role admin; the role write changes and deletes only the "
                                       "caller's own grids ('bob')"));
  const absl::Status fair = bob->Fair("alices", 0, nullptr, true).status();
  ExpectCode(fair, absl::StatusCode::kPermissionDenied);
  EXPECT_THAT(fair.message(), HasSubstr("fairing it needs the role admin"));
  const absl::Status deformed = bob->Deform(deform).status();
  ExpectCode(deformed, absl::StatusCode::kPermissionDenied);
  EXPECT_THAT(deformed.message(), HasSubstr("deforming it needs the role admin"));
  EXPECT_EQ(alice->Get("alices").value().latest_revision(), 1);  // nothing stored

  EXPECT_EQ(alice->Deform(deform).value().revision(), 2);
  EXPECT_EQ(admin->Deform(deform).value().revision(), 3);
  EXPECT_TRUE(admin->Fair("alices", 1, nullptr, true).ok());  // the fit, not a deformed one
}

TEST_F(AuthTest, AReloadChangesRolesAndABadFileKeepsThem) {
  auto carol = As("read-token-r1");
  ExpectCode(Import(*carol, "by-carol").status(), absl::StatusCode::kPermissionDenied);
  std::map<std::string, std::string> tokens = Tokens();
  tokens["read-token-r1"] = "carol write";
  tokens.erase("write-token-b1");
  WriteTokens(tokens);
  EXPECT_EQ(server_->ReloadTokens().value(), 3);
  EXPECT_TRUE(Import(*carol, "by-carol").ok());
  ExpectCode(As("write-token-b1")->List().status(), absl::StatusCode::kUnauthenticated);

  std::ofstream(dir_ / "tokens") << "read-token-r1 carol\n";  // two fields
  EXPECT_THAT(server_->ReloadTokens().status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "tokens:1: expected"));
  EXPECT_TRUE(carol->Get("by-carol").ok());  // the previous table still holds
  EXPECT_EQ(server_->state().authenticator.num_tokens(), 3);
}

// A reload that removes a token or lowers its role ends that token's open watches at once (an
// idle watch too), before anything more is sent; the other watches go on.
TEST_F(AuthTest, AReloadEndsTheWatchesOfTokensItRemoved) {
  auto alice = As("write-token-a1");
  ASSERT_TRUE(Import(*alice, "watched").ok());
  v1::FitSpec spec;
  spec.set_allow_folds(true);
  spec.mutable_control_counts()->set_i(12);
  spec.mutable_control_counts()->set_j(8);
  ASSERT_TRUE(alice->Fit("watched", spec).ok());
  auto carol = As("read-token-r1");
  auto bob = As("write-token-b1");
  std::unique_ptr<client::RevisionStream> removed = carol->Watch("watched", 0);
  std::unique_ptr<client::RevisionStream> lowered = bob->Watch("watched", 0);
  std::unique_ptr<client::RevisionStream> kept = alice->Watch("watched", 0);
  v1::WatchGridResponse message;
  for (auto* watch : {removed.get(), lowered.get(), kept.get()}) {
    ASSERT_TRUE(watch->Next(&message));  // revision 1; then they wait
  }
  std::map<std::string, std::string> tokens = Tokens();
  tokens.erase("read-token-r1");
  tokens["write-token-b1"] = "robert write";  // the same token now names someone else
  WriteTokens(tokens);
  ASSERT_EQ(server_->ReloadTokens().value(), 3);
  EXPECT_FALSE(removed->Next(&message));
  EXPECT_THAT(removed->Finish(),
              StatusIs(absl::StatusCode::kUnauthenticated,
                       "the tokens file was reloaded and this watch's token is no longer in it"));
  EXPECT_FALSE(lowered->Next(&message));
  EXPECT_THAT(lowered->Finish(), StatusIs(absl::StatusCode::kPermissionDenied,
                                          "now names robert with the role write"));
  ASSERT_TRUE(alice->Fit("watched", spec).ok());
  ASSERT_TRUE(kept->Next(&message));
  EXPECT_EQ(message.revision().revision(), 2);
  kept->Cancel();
}

TEST_F(AuthTest, GridsMadeWithoutTokensBelongToNoOneAndOwnersSurviveARestart) {
  // A durable store, first without tokens: the grid has no owner.
  options_.store = absl::StrCat("dir:", (dir_ / "store").string());
  options_.tokens_file = "";
  StartServer();
  ASSERT_TRUE(Import(*client_, "anonymous").ok());
  EXPECT_EQ(client_->Get("anonymous").value().owner(), "");
  // Then with tokens: alice's grid keeps her name across a restart.
  options_.tokens_file = (dir_ / "tokens").string();
  StartServer();
  ASSERT_TRUE(Import(*As("write-token-a1"), "alices").ok());
  StartServer();
  auto alice = As("write-token-a1");
  EXPECT_EQ(alice->Get("alices").value().owner(), "alice");
  ExpectCode(alice->Delete("anonymous"), absl::StatusCode::kPermissionDenied);
  ExpectCode(As("write-token-b1")->Delete("alices"), absl::StatusCode::kPermissionDenied);
  // An archive imported by a writer is that writer's copy, whoever exported it.
  const std::string archive = (dir_ / "alices.sgrid").string();
  ASSERT_TRUE(alice->ExportGrid("alices", archive).ok());
  auto bob = As("write-token-b1");
  const absl::StatusOr<v1::Grid> copy = bob->ImportArchive(archive, "bobs-copy");
  ASSERT_TRUE(copy.ok()) << copy.status();
  EXPECT_EQ(copy->owner(), "bob");
  EXPECT_TRUE(bob->Delete("bobs-copy").ok());
  // Imported by an admin (a restore), it stays alice's: she may go on changing it.
  auto admin = As("admin-token-z1");
  const absl::StatusOr<v1::Grid> restored = admin->ImportArchive(archive, "restored");
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(restored->owner(), "alice");
  v1::FitSpec spec;
  spec.set_allow_folds(true);
  spec.mutable_control_counts()->set_i(12);
  spec.mutable_control_counts()->set_j(8);
  const absl::StatusOr<v1::FitGridResponse> refit = alice->Fit("restored", spec);
  EXPECT_TRUE(refit.ok()) << refit.status();
  ExpectCode(bob->Delete("restored"), absl::StatusCode::kPermissionDenied);
  EXPECT_TRUE(alice->Delete("restored").ok());
  EXPECT_TRUE(alice->Delete("alices").ok());
  EXPECT_TRUE(As("admin-token-z1")->Delete("anonymous").ok());
}

TEST_F(AuthTest, AServerWithABadTokensFileDoesNotStart) {
  std::ofstream(dir_ / "bad") << "# ok\nsome-token-123 dave superuser\n";
  server::ServerOptions options = options_;
  options.tokens_file = (dir_ / "bad").string();
  const absl::Status status = server::Server::Start(options).status();
  EXPECT_THAT(status,
              StatusIs(absl::StatusCode::kInvalidArgument, "bad:2: the third field (the role)"));
  EXPECT_THAT(std::string(status.message()), Not(HasSubstr("some-token-123")));
}

}  // namespace
}  // namespace splinegrid::testing
