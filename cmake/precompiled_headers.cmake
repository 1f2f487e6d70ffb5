# Precompiled headers: the heavy third-party headers (Eigen, Catch2, nlohmann::json, pybind11)
# are parsed once per target instead of once per source file (benchmarks/RESULTS.md, first
# build). Only headers every source of the
# target may see first: no target defines a macro that changes them (EIGEN_*, CATCH_CONFIG_*).
# BUCKLE_PCH=OFF builds without them (e.g. to check that every file includes what it uses).
option(BUCKLE_PCH "Precompile the third-party headers of each target" ON)

# ccache caches a file compiled against a precompiled header only with this sloppiness
# (ccache's manual, "Precompiled headers"); CMake passes the header with -include.
if(BUCKLE_PCH AND CMAKE_CXX_COMPILER_LAUNCHER MATCHES "ccache")
  set(CMAKE_CXX_COMPILER_LAUNCHER ${CMAKE_COMMAND} -E env CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
      ${CMAKE_CXX_COMPILER_LAUNCHER})
endif()

set(BUCKLE_PCH_STD <algorithm> <cmath> <limits> <memory> <stdexcept> <string> <vector>)
# Eigen with its decompositions of MatrixXd declared as instantiated in buckle::continuation: for
# targets that link it. Named by its include path, not its absolute one, so the cmake_pch.hxx
# CMake writes has the same text in every clone. (GCC's .gch still differs between clones, so
# files compiled against it miss ccache in a fresh clone: benchmarks/RESULTS.md, Build.)
set(BUCKLE_PCH_EIGEN <buckle/continuation/internal/eigen_instances.h>)

# buckle_precompile(target header...): precompile the standard headers above and the given ones
# for `target`.
function(buckle_precompile target)
  if(BUCKLE_PCH)
    target_precompile_headers(${target} PRIVATE ${BUCKLE_PCH_STD} ${ARGN})
  endif()
endfunction()
