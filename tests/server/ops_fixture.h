// The operations layer (server/ops) under test on its own: a real MemoryStore, memory budget and
// deformer cache behind one OpsContext, and the shared NACA 0012 C-grid imported through it.
#ifndef SPLINEGRID_TESTS_SERVER_OPS_FIXTURE_H_
#define SPLINEGRID_TESTS_SERVER_OPS_FIXTURE_H_

#include <string>

#include "core/io/plot3d.h"
#include "gtest/gtest.h"
#include "server/ops/fit.h"
#include "server/ops/import.h"
#include "server/ops/ops_context.h"
#include "server/store/memory_store.h"
#include "tests/core/test_data.h"

namespace splinegrid::server {

// The NACA 0012 C-grid, 225 x 65.
inline MultiBlockGrid Naca() {
  return ReadPlot3dFile(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
}

class OpsFixture : public ::testing::Test {
 protected:
  // Imports Naca() as grid `id` (as ImportGrid does) and fits it `fits` times by kind.
  void AddNaca(const std::string& id, int fits) {
    ops::ImportedSource source;
    source.imported.grid = Naca();
    source.imported.format = "plot3d";
    ASSERT_TRUE(ops::StoreImported(ops_, {id, "", ""}, std::move(source)).ok());
    GridFitOptions options;
    options.boundary_tolerances = BoundaryTolerances();
    for (int f = 0; f < fits; ++f) ASSERT_TRUE(ops::Fit(ops_, id, options, {}).ok());
  }

  MemoryStore store_{/*max_deform_revisions=*/4};
  MemoryBudget budget_{int64_t{1} << 30};
  DeformerCache deformers_;
  const ops::OpsContext ops_{store_, budget_, deformers_};
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_TESTS_SERVER_OPS_FIXTURE_H_
