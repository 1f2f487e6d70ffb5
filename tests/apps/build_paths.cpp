#include "build_paths.h"

namespace buckle::test {
const char* sourceDir() { return BUCKLE_SOURCE_PATH; }
const char* binaryDir() { return BUCKLE_BINARY_PATH; }
}  // namespace buckle::test
