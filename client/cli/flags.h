// Flags of the `splinegrid` tool (defined in flags.cc).
#ifndef SPLINEGRID_CLIENT_CLI_FLAGS_H_
#define SPLINEGRID_CLIENT_CLI_FLAGS_H_

#include <cstdint>
#include <optional>
#include <string>

#include "absl/flags/declare.h"
#include "absl/time/time.h"

// Client side.
ABSL_DECLARE_FLAG(std::string, server);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(absl::Duration, timeout);
// Security: tokens and TLS (client side; --tls_cert/--tls_key are the server's with serve).
ABSL_DECLARE_FLAG(std::string, token);
ABSL_DECLARE_FLAG(std::string, tls_ca);
ABSL_DECLARE_FLAG(std::string, tls_cert);
ABSL_DECLARE_FLAG(std::string, tls_key);
ABSL_DECLARE_FLAG(std::string, tls_server_name);
// serve: security
ABSL_DECLARE_FLAG(std::string, tls_client_ca);
ABSL_DECLARE_FLAG(bool, insecure);
ABSL_DECLARE_FLAG(std::string, tokens);
// fit
ABSL_DECLARE_FLAG(std::string, name);
ABSL_DECLARE_FLAG(double, tol);
ABSL_DECLARE_FLAG(std::string, ctl);
ABSL_DECLARE_FLAG(int, order);
ABSL_DECLARE_FLAG(bool, planar);
ABSL_DECLARE_FLAG(std::string, plot3d_layout);
ABSL_DECLARE_FLAG(int, max_ctl);
ABSL_DECLARE_FLAG(bool, kinds);
ABSL_DECLARE_FLAG(double, wall);
ABSL_DECLARE_FLAG(double, interface);
ABSL_DECLARE_FLAG(double, outer);
ABSL_DECLARE_FLAG(double, interior);
ABSL_DECLARE_FLAG(double, edge);
ABSL_DECLARE_FLAG(double, first_layer);
ABSL_DECLARE_FLAG(std::string, fair);
ABSL_DECLARE_FLAG(double, ref_length);
ABSL_DECLARE_FLAG(std::string, face);
ABSL_DECLARE_FLAG(bool, allow_folds);
// get
ABSL_DECLARE_FLAG(int64_t, revision);
ABSL_DECLARE_FLAG(bool, full);
// eval
ABSL_DECLARE_FLAG(std::optional<int>, level);
ABSL_DECLARE_FLAG(std::string, res);
ABSL_DECLARE_FLAG(std::string, block);
ABSL_DECLARE_FLAG(std::string, box);
ABSL_DECLARE_FLAG(std::string, dist);
ABSL_DECLARE_FLAG(std::string, o);
ABSL_DECLARE_FLAG(bool, derivs);
ABSL_DECLARE_FLAG(bool, float32);
ABSL_DECLARE_FLAG(std::string, steps);
ABSL_DECLARE_FLAG(bool, compress);
ABSL_DECLARE_FLAG(int64_t, max_memory_mb);
ABSL_DECLARE_FLAG(bool, jacobian);
ABSL_DECLARE_FLAG(bool, quality);
ABSL_DECLARE_FLAG(bool, deviation);
// deform
ABSL_DECLARE_FLAG(std::optional<double>, rotate);
ABSL_DECLARE_FLAG(std::string, about);
ABSL_DECLARE_FLAG(std::string, axis);
ABSL_DECLARE_FLAG(std::string, translate);
ABSL_DECLARE_FLAG(std::string, boundary);
ABSL_DECLARE_FLAG(int64_t, reference);
ABSL_DECLARE_FLAG(int64_t, base);
ABSL_DECLARE_FLAG(double, time);
ABSL_DECLARE_FLAG(std::optional<int64_t>, step);
ABSL_DECLARE_FLAG(int, check_level);
ABSL_DECLARE_FLAG(std::string, propagation);
ABSL_DECLARE_FLAG(double, decay_radius);
ABSL_DECLARE_FLAG(double, rigid_radius);
ABSL_DECLARE_FLAG(int, smoothing);
// offset
ABSL_DECLARE_FLAG(std::optional<int>, layers);
ABSL_DECLARE_FLAG(std::optional<double>, first);
ABSL_DECLARE_FLAG(std::optional<double>, far);
ABSL_DECLARE_FLAG(std::optional<int>, points);
ABSL_DECLARE_FLAG(std::string, method);
ABSL_DECLARE_FLAG(std::optional<bool>, orthogonalize);
ABSL_DECLARE_FLAG(std::optional<double>, profile_tol);
ABSL_DECLARE_FLAG(std::string, side);
ABSL_DECLARE_FLAG(std::optional<int>, normal_smoothing);
ABSL_DECLARE_FLAG(std::optional<bool>, symmetry);
// watch
ABSL_DECLARE_FLAG(int64_t, after);
// health
ABSL_DECLARE_FLAG(std::string, service);
// serve
ABSL_DECLARE_FLAG(std::string, address);
ABSL_DECLARE_FLAG(std::string, store);
ABSL_DECLARE_FLAG(std::string, redis_password_file);
ABSL_DECLARE_FLAG(int, threads);
ABSL_DECLARE_FLAG(int64_t, memory_budget_mb);
ABSL_DECLARE_FLAG(absl::Duration, import_idle_timeout);
ABSL_DECLARE_FLAG(std::string, cgns_decoder);
ABSL_DECLARE_FLAG(int64_t, cgns_decoder_memory_mb);
ABSL_DECLARE_FLAG(int64_t, cgns_decoder_cpu_seconds);
ABSL_DECLARE_FLAG(int64_t, cgns_decoder_timeout_seconds);
ABSL_DECLARE_FLAG(int64_t, max_output_points);
ABSL_DECLARE_FLAG(absl::Duration, shutdown_grace);
ABSL_DECLARE_FLAG(bool, log_calls);
ABSL_DECLARE_FLAG(std::string, log_format);
ABSL_DECLARE_FLAG(absl::Duration, drain_notice);
ABSL_DECLARE_FLAG(int, keep_revisions);
// serve: fair scheduling and per-principal limits
ABSL_DECLARE_FLAG(int, max_running_long_tasks);
ABSL_DECLARE_FLAG(int, max_queued_long_calls_per_principal);
ABSL_DECLARE_FLAG(int, max_streams_per_principal);
// serve: the Prometheus endpoint (server/metrics_endpoint.h)
ABSL_DECLARE_FLAG(std::string, metrics_address);
ABSL_DECLARE_FLAG(bool, metrics_insecure);

#endif  // SPLINEGRID_CLIENT_CLI_FLAGS_H_
