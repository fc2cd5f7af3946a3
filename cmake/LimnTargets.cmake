# limn_module(NAME SOURCES ... DEPS ...): a static library for one folder of the tree.
function(limn_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
endfunction()

# limn_test(NAME SOURCES ... DEPS ...): one GoogleTest executable registered with CTest.
# Tests find their data through LIMN_SOURCE_DIR (tests/data, ../shared/corpus).
# SLOW marks a program whose cases take minutes (the corpus at 1024^2): they carry the CTest
# label "slow", which `scripts/test.sh --quick` leaves out.
# HEAVY marks a program of many full renders at a few hundred pixels whose engine code the unit
# suites also cover: label "heavy" as well, which scripts/sanitize.sh leaves out (under the
# sanitizers each such program takes minutes).
# SHARDS n: CTest runs the program as n processes, each taking every n-th case (GoogleTest
# sharding), so that long programs spread over the cores; each shard is one CTest test. Without
# it the program is one test.
function(limn_test name)
  cmake_parse_arguments(ARG "SLOW;HEAVY" "SHARDS" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE LIMN_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(ARG_SLOW)
    set(label slow)
  else()
    set(label quick)
  endif()
  if(ARG_HEAVY)
    list(APPEND label heavy)
  endif()
  # One CTest test per shard of the program (default: the whole program), not one per test
  # case: a process per case paid the program's start (linking and initialising OpenSubdiv,
  # Embree, OpenImageIO, Mesa) 286 times, about twice the unit tests' own run time. A failing
  # case is named in the program's output (ctest --output-on-failure); run one case with
  # build/bin/PROGRAM --gtest_filter=NAME.
  if(NOT ARG_SHARDS)
    set(ARG_SHARDS 1)
  endif()
  math(EXPR last "${ARG_SHARDS} - 1")
  foreach(shard RANGE ${last})
    add_test(NAME ${name}/shard${shard} COMMAND ${name})
    set_tests_properties(${name}/shard${shard} PROPERTIES
      ENVIRONMENT "GTEST_TOTAL_SHARDS=${ARG_SHARDS};GTEST_SHARD_INDEX=${shard}"
      TIMEOUT 1800 LABELS "${label}")
  endforeach()
endfunction()
