// GenerateGrid: the request converted (proto/convert/generate_convert.h) and handed to the
// operation (server/ops/generate.h), on the pool.
#include <chrono>

#include "core/io/airfoil.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/generate_convert.h"
#include "server/grid_encoding.h"
#include "server/ops/generate.h"
#include "server/ops/generate_volume.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

absl::StatusOr<std::variant<ops::ProfilePoints, ops::StoredWall>> ParseProfile(
    const v1::GenerateGridRequest& request) {
  switch (request.profile_case()) {
    case v1::GenerateGridRequest::kPoints: {
      ops::ProfilePoints points;
      SG_ASSIGN_OR_RETURN(points.points, ParseProfilePoints(request.points(), "points"));
      return points;
    }
    case v1::GenerateGridRequest::kAirfoilFile: {
      SG_ASSIGN_OR_RETURN(AirfoilCoordinates file,
                          ParseAirfoil(request.airfoil_file(), "airfoil_file"));
      return ops::ProfilePoints{std::move(file.points), std::move(file.name)};
    }
    case v1::GenerateGridRequest::kStoredSurface:  // GenerateVolume's (below)
      break;
    case v1::GenerateGridRequest::kStoredWall: {
      ops::StoredWall wall;
      SG_ASSIGN_OR_RETURN(wall.grid_id,
                          ParseGridName(request.stored_wall().name(), "stored_wall.name"));
      wall.revision = request.stored_wall().revision();
      wall.block = request.stored_wall().block();
      return wall;
    }
    case v1::GenerateGridRequest::PROFILE_NOT_SET:
      break;
  }
  return absl::InvalidArgumentError("profile is unset: give points, airfoil_file or stored_wall");
}

absl::StatusOr<ops::GenerateRequest> ParseRequest(const v1::GenerateGridRequest& request) {
  ops::GenerateRequest out;
  out.grid_id = request.grid_id();
  out.display_name = request.display_name();
  SG_ASSIGN_OR_RETURN(out.options, ParseProfileGridOptions(request));
  if (request.has_spec()) {
    SG_ASSIGN_OR_RETURN(out.fit, ParseFitSpec(request.spec()));
  }
  out.allow_folds = request.allow_folds();
  SG_ASSIGN_OR_RETURN(out.profile, ParseProfile(request));
  return out;
}

absl::StatusOr<ops::GenerateVolumeRequest> ParseVolumeRequest(
    const v1::GenerateGridRequest& request) {
  ops::GenerateVolumeRequest out;
  out.grid_id = request.grid_id();
  out.display_name = request.display_name();
  SG_ASSIGN_OR_RETURN(out.options, ParseSurfaceOffsetOptions(request));
  if (request.has_spec()) {
    SG_ASSIGN_OR_RETURN(out.fit, ParseFitSpec(request.spec()));
  }
  out.allow_folds = request.allow_folds();
  SG_ASSIGN_OR_RETURN(out.surface.grid_id,
                      ParseGridName(request.stored_surface().name(), "stored_surface.name"));
  out.surface.revision = request.stored_surface().revision();
  return out;
}

// A volume grid off a stored surface: parsed, generated and encoded.
absl::Status GenerateVolumeGrid(const ops::OpsContext& ops, const v1::GenerateGridRequest& request,
                                const Caller& caller, int64_t max_points, const CancelCheck& cancel,
                                v1::GenerateGridResponse* response) {
  SG_ASSIGN_OR_RETURN(ops::GenerateVolumeRequest generate, ParseVolumeRequest(request));
  generate.owner = caller.owner();
  generate.max_points = max_points;
  SG_ASSIGN_OR_RETURN(const ops::GenerateVolumeResult result,
                      ops::GenerateVolume(ops, std::move(generate), cancel));
  v1::GenerationReport* report = response->mutable_report();
  std::vector<Extents> extents;
  for (const StructuredBlock& block : result.grid->source->grid().blocks) {
    extents.push_back(block.extents());
  }
  EncodeVolumeReport(result.generated, extents, result.reversed_i, report->mutable_volume());
  EncodeSurfaceOffsetOptions(result.options, report->mutable_parameters());
  report->set_growth_ratio(result.generated.growth_ratio);
  report->set_retries(result.generated.retries);
  report->set_layer_seconds(result.layer_seconds);
  SG_RETURN_IF_ERROR(
      EncodeGrid(*result.grid, 0, v1::GRID_VIEW_BASIC, {}, response->mutable_grid()));
  EncodeFitResponse(*result.grid->revisions.back(), response->mutable_fit());
  return absl::OkStatus();
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::GenerateGrid(grpc::CallbackServerContext* context,
                                                          const v1::GenerateGridRequest* request,
                                                          v1::GenerateGridResponse* response) {
  CallLog log("GenerateGrid", request->grid_id().empty() ? "" : "grids/" + request->grid_id(),
              state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(
      context, log, Role::kWrite, WorkKind::kLong,
      [this, request, response, cancel](const Caller& caller) -> absl::Status {
        const auto start = std::chrono::steady_clock::now();
        auto seconds = [&] {
          return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        };
        if (request->has_stored_surface()) {
          SG_RETURN_IF_ERROR(GenerateVolumeGrid(
              Ops(), *request, caller, state_->options.max_output_points, cancel, response));
          response->mutable_report()->set_seconds(seconds());
          return absl::OkStatus();
        }
        SG_ASSIGN_OR_RETURN(ops::GenerateRequest generate, ParseRequest(*request));
        generate.owner = caller.owner();
        generate.max_points = state_->options.max_output_points;
        SG_ASSIGN_OR_RETURN(const ops::GenerateResult result,
                            ops::Generate(Ops(), std::move(generate), cancel));
        v1::GenerationReport* report = response->mutable_report();
        EncodeGenerationReport(result.generated, result.grid->source->grid().blocks[0].extents(),
                               result.profile_points, report);
        EncodeProfileGridOptions(result.options, report->mutable_parameters());
        report->mutable_profile()->set_name(result.profile_name);
        SG_RETURN_IF_ERROR(
            EncodeGrid(*result.grid, 0, v1::GRID_VIEW_BASIC, {}, response->mutable_grid()));
        EncodeFitResponse(*result.grid->revisions.back(), response->mutable_fit());
        report->set_seconds(seconds());
        return absl::OkStatus();
      });
}

}  // namespace splinegrid::server
