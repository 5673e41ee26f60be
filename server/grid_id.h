// What a grid id is: the {id} of "grids/{id}".
#ifndef SPLINEGRID_SERVER_GRID_ID_H_
#define SPLINEGRID_SERVER_GRID_ID_H_

#include <string>

namespace splinegrid::server {

// Whether `id` is a valid grid id: 1-63 characters of [a-z0-9-], starting with a letter.
bool IsValidGridId(const std::string& id);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_ID_H_
