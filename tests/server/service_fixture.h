// An in-process splinegrid server and client for service tests.
#ifndef SPLINEGRID_TESTS_SERVER_SERVICE_FIXTURE_H_
#define SPLINEGRID_TESTS_SERVER_SERVICE_FIXTURE_H_

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "client/client.h"
#include "core/io/file_util.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/server.h"
#include "tests/core/test_data.h"

namespace splinegrid::testing {

// A status with `code` whose message contains `fragment`.
MATCHER_P2(StatusIs, code, fragment, "") {
  const absl::Status status = arg;
  *result_listener << "status " << status;
  return status.code() == code && status.message().find(fragment) != std::string::npos;
}

class ServiceTest : public ::testing::Test {
 protected:
  // Options of the server under test; tests may change them before StartServer().
  server::ServerOptions options_ = [] {
    server::ServerOptions o;
    o.address = "";  // in-process only
    o.log_calls = false;
    o.worker_threads = 2;
    return o;
  }();

  void SetUp() override { StartServer(); }

  void StartServer() {
    server_.reset();
    server_ = server::Server::Start(options_).value();
    client::ClientOptions client_options;
    client_options.timeout = absl::Seconds(60);
    client_ = std::make_unique<client::Client>(server_->InProcessChannel(), client_options);
  }

  // Imports a shared Plot3D file under `id` (planar view for two-plane files).
  v1::Grid ImportShared(const std::string& relative, const std::string& id, bool planar = false) {
    const std::string bytes = ReadFileToString(SharedDataPath(relative)).value();
    absl::StatusOr<v1::Grid> grid = client_->ImportPlot3d(bytes, id, relative, planar);
    EXPECT_TRUE(grid.ok()) << grid.status();
    return grid.ok() ? *grid : v1::Grid();
  }

  // Fits `id` with `counts` control points per direction (0: interpolation). Folds are
  // accepted (allow_folds): the tests using this fit test something else, and some counts fold
  // the shared grids at levels 1-2 (see fold_refusal_test.cc for the refusal).
  v1::FitGridResponse FitCounts(const std::string& id, int ci, int cj, int ck = 0) {
    v1::FitSpec spec;
    spec.set_allow_folds(true);
    spec.mutable_control_counts()->set_i(ci);
    spec.mutable_control_counts()->set_j(cj);
    spec.mutable_control_counts()->set_k(ck);
    absl::StatusOr<v1::FitGridResponse> fit = client_->Fit(id, spec);
    EXPECT_TRUE(fit.ok()) << fit.status();
    return fit.ok() ? *fit : v1::FitGridResponse();
  }

  // Waits until the memory budget is back to `bytes` (in-flight work released), up to 5 s.
  // The budget once the calls that just returned have let go of their reservations (a server
  // releases a call's reservation after the client has seen its status): unchanged for 50 ms.
  int64_t SettledBudget() {
    int64_t used = server_->state().budget.used();
    for (int i = 0; i < 100; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      const int64_t now = server_->state().budget.used();
      if (now == used) break;
      used = now;
    }
    return used;
  }

  bool WaitForBudget(int64_t bytes) {
    for (int i = 0; i < 500; ++i) {
      if (server_->state().budget.used() == bytes) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  // Every grid's name, in order.
  std::vector<std::string> GridNames() {
    std::vector<std::string> names;
    const std::vector<v1::Grid> grids = client_->List().value();
    for (const v1::Grid& g : grids) names.push_back(g.name());
    return names;
  }

  // A GenerateGrid call refused with `code` and a message holding `fragment`: nothing stored,
  // the memory budget back where it was.
  void ExpectGenerateRefused(const v1::GenerateGridRequest& request, absl::StatusCode code,
                             const std::string& fragment) {
    const std::vector<std::string> before = GridNames();
    const int64_t budget = SettledBudget();
    EXPECT_THAT(client_->Generate(request).status(), StatusIs(code, fragment));
    EXPECT_EQ(GridNames(), before);
    EXPECT_TRUE(WaitForBudget(budget));
  }

  std::unique_ptr<server::Server> server_;
  std::unique_ptr<client::Client> client_;
};

}  // namespace splinegrid::testing

#endif  // SPLINEGRID_TESTS_SERVER_SERVICE_FIXTURE_H_
