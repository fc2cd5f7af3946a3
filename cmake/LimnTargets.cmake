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
function(limn_test name)
  cmake_parse_arguments(ARG "SLOW" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE LIMN_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(ARG_SLOW)
    set(label slow)
  else()
    set(label quick)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 1200 LABELS ${label})
endfunction()
