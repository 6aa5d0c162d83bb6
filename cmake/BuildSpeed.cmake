# How the build stays fast on a 2-core machine (README "Build times" has the figures).
#
# - ccache, when installed, caches every compilation (scripts/install-deps.sh installs it).
#   Precompiled headers need its pch_defines,time_macros sloppiness; CCACHE_BASEDIR makes
#   two checkouts at the same depth share the cache. Depend mode (CCACHE_DEPEND): a miss
#   compiles once, without running the preprocessor first to hash its output (the compiler's
#   -MD list is hashed instead), which is every compilation of a fresh machine: the TSan
#   build's 41 compilations took 216 CPU-s without ccache, 228 through a cold cache in the
#   default mode and 213 in depend mode; a warm rebuild hits directly as before.
# - sweetspot_precompile(<target> <headers>...): the heavy third-party headers (Eigen,
#   nlohmann-json, GoogleTest, Boost.Odeint) are parsed once per target instead of once per
#   source file.
# - sweetspot_unity(<target>): the libraries, test and benchmark programs are unity builds
#   (their sources compiled in batches, so the headers and the templates they share are
#   compiled once per batch: core, api and the server library compile in about half the
#   time, README "Build times"). A name in a file's anonymous namespace must therefore not
#   be declared by another file of the same target: the compiler says so at once
#   ("redefinition of ...", "ambiguous"); shared constants live in one header
#   (core/numerics/limits.hpp). SWEETSPOT_UNITY_BATCH sets the batch size of the libraries
#   and benchmarks, SWEETSPOT_TEST_UNITY_BATCH that of the test programs (64: one batch per
#   program today, core_tests' 58 files the largest: their batches at -O0 spend most of their
#   time on the templates of GoogleTest, Eigen and nlohmann-json that every batch instantiates
#   and emits again, so fewer, larger batches do that less often: two of core_tests' batches of 8
#   took 32.7 CPU-seconds with GCC, the same 16 files in one batch 26.7; core_tests, api_tests
#   and server_tests took 116 CPU-s with GCC in batches of 16 and 77 in batches of 64,
#   README "Build times"); -DSWEETSPOT_UNITY=OFF compiles file by file (quicker rebuilds
#   while editing one file), -DSWEETSPOT_TEST_UNITY_BATCH=8 recompiles less of a test program.
# - sweetspot_test_flags(<target>): test programs compile at SWEETSPOT_TEST_OPTIMIZE (-O0 by
#   default). The code under test keeps the build type's flags (-O3 in Release, -O2 in the
#   ASan build, -O1 in the TSan build): only the test drivers are cheaper to compile (a test
#   program's batch compiles in about 40 % of its time at -O1, README "Build times"), and
#   sweetspot_libraries_first keeps their unoptimised copies of shared templates out of the
#   libraries' way. Benchmarks keep the build type's flags (they time header code).
# - sweetspot_libraries_first(<target> <libraries>...): a test program links the code under
#   test ahead of its own objects, so the optimised library's copy of each shared template
#   function (Eigen's kernels) is the one the linker keeps. Otherwise the first copy the
#   linker meets wins, the test driver's unoptimised one, and the library's calls go to it:
#   under ASan that made OptimizeSting.TheSameSeedGivesTheSameAnswer take 55 s instead of
#   22 s (README "Build times").
# - lld, when installed (scripts/install-deps.sh installs it), links every program: the
#   sanitizer builds' programs carry line tables and the sanitizer runtimes, and GNU ld took
#   1.86 CPU-seconds to link the ASan server_tests against lld's 0.41 (gold 0.99), the TSan
#   server_tests 1.25 against 0.24, a fuzz target 1.03 against 0.26; each build ends on such
#   links. lld keeps the first copy of a template function
#   it meets, as GNU ld does, so sweetspot_libraries_first works the same.

option(SWEETSPOT_CCACHE "Compile through ccache when it is installed" ON)
option(SWEETSPOT_PCH "Precompile the heavy third-party headers" ON)
option(SWEETSPOT_UNITY "Compile the libraries, test and benchmark programs as unity builds" ON)
set(SWEETSPOT_UNITY_BATCH 8 CACHE STRING "Source files per unity batch of a library or benchmark")
set(SWEETSPOT_TEST_UNITY_BATCH 64 CACHE STRING "Source files per unity batch of a test program")
set(SWEETSPOT_TEST_OPTIMIZE -O0 CACHE STRING
    "Optimisation flag of the test programs (empty: the build type's)")
option(SWEETSPOT_LLD "Link with lld when it is installed" ON)

if(SWEETSPOT_LLD)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=lld SWEETSPOT_LINKER_LLD)
  if(SWEETSPOT_LINKER_LLD)
    add_link_options(-fuse-ld=lld)
  endif()
endif()

if(SWEETSPOT_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(SWEETSPOT_CCACHE_EXECUTABLE ccache)
  if(SWEETSPOT_CCACHE_EXECUTABLE)
    get_filename_component(sweetspot_checkouts ${PROJECT_SOURCE_DIR} DIRECTORY)
    set(CMAKE_CXX_COMPILER_LAUNCHER
        ${CMAKE_COMMAND} -E env
        CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
        CCACHE_DEPEND=1 CCACHE_BASEDIR=${sweetspot_checkouts} ${SWEETSPOT_CCACHE_EXECUTABLE})
    message(STATUS "Compiling through ${SWEETSPOT_CCACHE_EXECUTABLE}")
  endif()
endif()

# sweetspot_precompile(<target> <header>...): precompiles the given headers for <target>
# (angle-bracket names, e.g. <Eigen/Dense>). PRIVATE: dependants precompile their own.
function(sweetspot_precompile target)
  if(SWEETSPOT_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# sweetspot_unity(<target> [BATCH <n>]): compiles a library, test or benchmark program in unity
# batches of <n> sources (default SWEETSPOT_UNITY_BATCH).
function(sweetspot_unity target)
  cmake_parse_arguments(PARSE_ARGV 1 UNITY "" "BATCH" "")
  if(NOT UNITY_BATCH)
    set(UNITY_BATCH ${SWEETSPOT_UNITY_BATCH})
  endif()
  if(SWEETSPOT_UNITY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON
                                               UNITY_BUILD_BATCH_SIZE ${UNITY_BATCH})
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # In a batch every source is an included file, so GCC takes a class with a field of
      # its file's anonymous-namespace type for a header's (-Wsubobject-linkage): not so here.
      target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
    endif()
  endif()
endfunction()

# sweetspot_test_flags(<target>): SWEETSPOT_TEST_OPTIMIZE for a test program.
function(sweetspot_test_flags target)
  if(SWEETSPOT_TEST_OPTIMIZE)
    # Appended after the build type's -O3/-O1, so it wins; the libraries keep theirs.
    target_compile_options(${target} PRIVATE ${SWEETSPOT_TEST_OPTIMIZE})
  endif()
endfunction()

# The headers each layer's sources share (and that cost the most to parse).
set(SWEETSPOT_PCH_STD <algorithm> <chrono> <cmath> <functional> <limits> <map> <memory>
                      <optional> <sstream> <string> <string_view> <utility> <vector>)
set(SWEETSPOT_PCH_CORE ${SWEETSPOT_PCH_STD} <Eigen/Core> <Eigen/Dense>)
set(SWEETSPOT_PCH_API ${SWEETSPOT_PCH_CORE} <nlohmann/json.hpp>)
set(SWEETSPOT_PCH_TESTS ${SWEETSPOT_PCH_API} <gtest/gtest.h>)

# sweetspot_libraries_first(<target> <library>...): links the static libraries <library>... and
# the sweetspot_* static libraries they depend on, whole, ahead of <target>'s own objects
# (see the top of this file). They stay in the ordinary link list too, where they add nothing.
function(sweetspot_libraries_first target)
  set(pending ${ARGN})
  set(archives)
  while(pending)
    list(POP_FRONT pending library)
    if(NOT library MATCHES "^sweetspot_" OR NOT TARGET ${library})
      continue()
    endif()
    get_target_property(type ${library} TYPE)
    if(NOT type STREQUAL "STATIC_LIBRARY" OR "$<TARGET_FILE:${library}>" IN_LIST archives)
      continue()
    endif()
    list(APPEND archives "$<TARGET_FILE:${library}>")
    get_target_property(dependencies ${library} LINK_LIBRARIES)
    if(dependencies)
      list(APPEND pending ${dependencies})
    endif()
  endwhile()
  if(archives)
    string(REPLACE ";" "," archive_list "${archives}")
    target_link_options(${target} BEFORE PRIVATE
                        "LINKER:--whole-archive,${archive_list},--no-whole-archive")
  endif()
endfunction()
