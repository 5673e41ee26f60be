// Where tests find data: the shared read-only data set and the project's own tests/data.
#ifndef SPLINEGRID_TESTS_CORE_TEST_DATA_H_
#define SPLINEGRID_TESTS_CORE_TEST_DATA_H_

#include <cstdlib>
#include <string>

namespace splinegrid {

// Path of `relative` in the shared data set: $SPLINEGRID_SHARED_DATA/relative when that
// environment variable is set and non-empty, else <source dir>/../shared/data/relative.
inline std::string SharedDataPath(const std::string& relative) {
  const char* root = std::getenv("SPLINEGRID_SHARED_DATA");
  if (root != nullptr && *root != '\0') return std::string(root) + "/" + relative;
  return std::string(SPLINEGRID_SOURCE_DIR "/../shared/data/") + relative;
}

// Path of `relative` in the project's own small fixtures, tests/data/.
inline std::string ProjectTestDataPath(const std::string& relative) {
  return std::string(SPLINEGRID_SOURCE_DIR "/tests/data/") + relative;
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_TEST_DATA_H_
