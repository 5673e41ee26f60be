// What a grid id is: the {id} of "grids/{id}".
#ifndef SPLINEGRID_SERVER_GRID_ID_H_
#define SPLINEGRID_SERVER_GRID_ID_H_

#include <string>

#include "absl/status/status.h"

namespace splinegrid::server {

// Whether `id` is a valid grid id: 1-63 characters of [a-z0-9-], starting with a letter.
bool IsValidGridId(const std::string& id);

// The id a request asks a new grid to get: OK when empty (the server picks one) or valid;
// INVALID_ARGUMENT naming `field` and the (quoted) value otherwise.
absl::Status CheckRequestedGridId(const std::string& id, const std::string& field);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_ID_H_
