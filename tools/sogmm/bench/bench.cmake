# `sogmm bench` (issue 6), included from tools/sogmm/CMakeLists.txt after the
# sogmm_cli target exists. OctoMap is optional: without it the OM rows are
# skipped and the bench says so.
add_library(sogmm_bench STATIC
  ${CMAKE_CURRENT_LIST_DIR}/ndt_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/octomap_adapter.cpp
  ${CMAKE_CURRENT_LIST_DIR}/runner.cpp
)
target_include_directories(sogmm_bench PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(sogmm_bench PUBLIC sogmm_tool_support sogmm_core)
if(TARGET sogmm_format)
  target_link_libraries(sogmm_bench PRIVATE sogmm_format)
  target_compile_definitions(sogmm_bench PRIVATE SOGMM_BENCH_HAVE_FORMAT=1)
endif()

option(SOGMM_WITH_OCTOMAP "Use liboctomap for the OctoMap rows of sogmm bench, when found" ON)
if(SOGMM_WITH_OCTOMAP)
  find_package(octomap QUIET)
endif()
if(SOGMM_WITH_OCTOMAP AND octomap_FOUND AND TARGET octomap)
  message(STATUS "sogmm bench: OctoMap ${octomap_VERSION} found, OM baseline enabled")
  target_link_libraries(sogmm_bench PRIVATE octomap octomath)
  target_compile_definitions(sogmm_bench PRIVATE SOGMM_HAVE_OCTOMAP=1 SOGMM_OCTOMAP_VERSION="${octomap_VERSION}")
  set(SOGMM_BENCH_HAVE_OCTOMAP ON CACHE INTERNAL "sogmm bench built with OctoMap")
else()
  message(STATUS "sogmm bench: OctoMap not found (liboctomap-dev), OM baseline disabled")
  set(SOGMM_BENCH_HAVE_OCTOMAP OFF CACHE INTERNAL "sogmm bench built with OctoMap")
endif()

target_sources(sogmm_cli PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../command_bench.cpp)
target_link_libraries(sogmm_cli PRIVATE sogmm_bench)
set_property(SOURCE ${CMAKE_CURRENT_LIST_DIR}/../command_bench.cpp APPEND PROPERTY COMPILE_DEFINITIONS
  SOGMM_BENCH_PLOT_SCRIPT="${CMAKE_CURRENT_LIST_DIR}/plot_bench.py")
