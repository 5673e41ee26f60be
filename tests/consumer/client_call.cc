// Links the installed C++ client (gRPC, Protobuf, the generated stubs) and makes one call that
// finds no server: UNAVAILABLE.
#include <cstdio>
#include <string>

#include "client/client.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  namespace client = splinegrid::client;
  if (client::GridName("naca") != "grids/naca") return 1;
  client::ClientOptions options;
  options.timeout = absl::Seconds(5);
  options.retry.max_attempts = 1;
  const auto connected = client::Client::Connect(argv[1], options);
  const absl::StatusOr<std::string> health = connected->Health();
  std::printf("client_call: %s\n", health.status().ToString().c_str());
  return absl::IsUnavailable(health.status()) ? 0 : 1;
}
