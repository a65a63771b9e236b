# drape_precompile(TARGET [HEADERS header...])
#
# Precompiles the standard, Eigen and fmt headers that nearly every file of the project
# includes, and HEADERS besides, so that each file of TARGET parses them once per target
# instead of once per file. Eigen alone is 130,000 lines after preprocessing; the optimised
# build took 18 instead of 20 minutes on two cores (most of the rest is optimising the code
# each file instantiates). DRAPE_PCH=OFF builds without; with DRAPE_UNITY=OFF as well, that
# shows a file that forgot an include of its own.
function(drape_precompile target)
  cmake_parse_arguments(ARG "" "" "HEADERS" ${ARGN})
  if(NOT DRAPE_PCH)
    return()
  endif()
  target_precompile_headers(${target} PRIVATE
    <algorithm> <array> <cmath> <cstdint> <filesystem> <fstream> <limits> <optional>
    <span> <string> <string_view> <vector> <Eigen/Core> <Eigen/Geometry> <fmt/format.h>
    ${ARG_HEADERS})
endfunction()

# drape_batch(TARGET)
#
# Compiles TARGET's files in two batches (CMake's unity build: each batch one translation unit
# that includes its files) instead of one by one. Most of a file's compile time goes to the
# CLI11, nlohmann_json, fmt, Eigen and GoogleTest templates it instantiates and optimises,
# again in every file; a batch does that once. Two batches, not one, so that both cores of
# a two-core machine have work while one target is all there is to build (the drape
# executable, which every test target waits for). The cli's 22 files took 4.4 minutes to
# build on two cores, and 1.2 in two batches. A file's names in its anonymous namespace
# therefore share a scope with its batch's other files: two files may not both define a
# helper of the same name.
# DRAPE_UNITY=OFF (with DRAPE_PCH=OFF) compiles every file alone, which shows a file that
# forgot an include of its own.
function(drape_batch target)
  if(NOT DRAPE_UNITY)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  list(LENGTH sources count)
  math(EXPR per_batch "(${count} + 1) / 2")
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${per_batch})
  # GCC takes the files a batch includes for headers, and warns of a class (a pimpl's Impl)
  # whose members' types sit in its file's anonymous namespace, which in a header would
  # differ from file to file. Here each file is its own, and compiled alone it is silent.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
  endif()
endfunction()

# drape_add_module(NAME [UNBATCHED] [DEPS target...])
#
# Builds src/NAME/*.cpp into the static library drape_NAME. Public headers live in
# src/NAME/include/drape/NAME/ and are included as <drape/NAME/header.hpp>. A module sees
# only the headers of the modules it links, so an upward include fails to compile.
# UNBATCHED compiles the module file by file even where DRAPE_UNITY batches the others.
function(drape_add_module name)
  cmake_parse_arguments(ARG "UNBATCHED" "" "DEPS" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp")
  add_library(drape_${name} STATIC ${sources})
  target_include_directories(drape_${name} PUBLIC "${CMAKE_CURRENT_SOURCE_DIR}/include")
  target_link_libraries(drape_${name} PUBLIC ${ARG_DEPS})
  add_library(drape::${name} ALIAS drape_${name})
  drape_precompile(drape_${name})
  if(NOT ARG_UNBATCHED)
    drape_batch(drape_${name})
  endif()
endfunction()

# drape_add_test(MODULE [TIMEOUT S] [COST C] [DEPS target...] [ENVIRONMENT VAR=VALUE])
#
# Builds tests/MODULE/*.cpp into test_MODULE, linked with the module's library (where there
# is one: tests/cli has none, it runs the executable) and DEPS, and registers each
# GoogleTest case with CTest. Tests find the project's data through DRAPE_DATA_DIR, the
# source tree through DRAPE_SOURCE_DIR and the built CLI through DRAPE_EXE, which is built
# before them. COST: CTest starts the tests of higher cost first when it runs several at once
# and has no times of its own yet (a clean build directory, as in CI), so modules that hold
# minutes-long scenarios say so and the short tests fill in at the end instead of one long
# test running alone.
function(drape_add_test module)
  cmake_parse_arguments(ARG "" "TIMEOUT;COST;ENVIRONMENT" "DEPS" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp")
  add_executable(test_${module} ${sources})
  set(libraries ${ARG_DEPS})
  if(TARGET drape::${module})
    list(PREPEND libraries drape::${module})
  endif()
  target_link_libraries(test_${module} PRIVATE ${libraries} GTest::gtest GTest::gtest_main)
  add_dependencies(test_${module} drape)
  set(headers <gtest/gtest.h>)
  if("nlohmann_json::nlohmann_json" IN_LIST ARG_DEPS)
    list(APPEND headers <nlohmann/json.hpp>)
  endif()
  drape_precompile(test_${module} HEADERS ${headers})
  drape_batch(test_${module})
  if(DRAPE_UNITY AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # Where a batch gives it more to inline, GCC warns that std::string's operator+ copies
    # past the end of its temporary's buffer, which it does not (the temporary grows
    # first): six test helpers that join a data directory and a file name, in the optimised
    # build. GCC 12 to 14 are reported to give these false positives on concatenations; the
    # sanitizer build checks the same code's memory accesses for real.
    target_compile_options(test_${module} PRIVATE
      -Wno-array-bounds -Wno-stringop-overflow -Wno-stringop-overread)
  endif()
  target_include_directories(test_${module} PRIVATE "${PROJECT_SOURCE_DIR}/tests/support/include")
  target_compile_definitions(test_${module} PRIVATE
    DRAPE_DATA_DIR="${DRAPE_DATA_DIR}"
    DRAPE_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    DRAPE_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data"
    DRAPE_EXE="$<TARGET_FILE:drape>")
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  set(properties TIMEOUT ${ARG_TIMEOUT})
  if(ARG_COST)
    list(APPEND properties COST ${ARG_COST})
  endif()
  if(ARG_ENVIRONMENT)
    list(APPEND properties ENVIRONMENT "${ARG_ENVIRONMENT}")
  endif()
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 PROPERTIES ${properties})
endfunction()
