// The checkout and build directories the tests run against. Defined in build_paths.cpp alone,
// the one file compiled with them: a path in every test source's compile definitions would make
// the objects of each clone differ, and a fresh clone could reuse none of them from ccache.
#pragma once

namespace buckle::test {
const char* sourceDir();
const char* binaryDir();
}  // namespace buckle::test

#define BUCKLE_SOURCE_DIR (::buckle::test::sourceDir())
#define BUCKLE_BINARY_DIR (::buckle::test::binaryDir())
