# Helpers shared by every module: warnings, sanitizers, one static library per concept folder.

set(UWB_WARNINGS -Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor)
if(UWB_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()

# uwb_add_module(<name> DEPS <targets...>)
# Builds src/<name>/*.cpp into the static library uwb_<name> (alias uwb::<name>) with public headers in
# include/uwb/<name>/. A module without sources yet is an INTERFACE library.
function(uwb_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS "${CMAKE_SOURCE_DIR}/src/${name}/*.cpp")
  if(srcs)
    add_library(uwb_${name} STATIC ${srcs})
    target_include_directories(uwb_${name} PUBLIC "${CMAKE_SOURCE_DIR}/include")
    target_link_libraries(uwb_${name} PUBLIC ${ARG_DEPS})
    target_compile_options(uwb_${name} PRIVATE ${UWB_WARNINGS})
  else()
    add_library(uwb_${name} INTERFACE)
    target_include_directories(uwb_${name} INTERFACE "${CMAKE_SOURCE_DIR}/include")
    target_link_libraries(uwb_${name} INTERFACE ${ARG_DEPS})
  endif()
  add_library(uwb::${name} ALIAS uwb_${name})
endfunction()

# uwb_add_gtest(<module> [LINK <target>] [LABELS ...])
# One test executable per module: tests/<module>/*Test.cpp -> test_<module>, registered with ctest.
# It links only its own module (default uwb_<module>), so a half-written module elsewhere does not block it.
function(uwb_add_gtest module)
  cmake_parse_arguments(ARG "" "LINK" "LABELS" ${ARGN})
  if(NOT ARG_LINK)
    set(ARG_LINK uwb_${module})
  endif()
  file(GLOB srcs CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/${module}/*Test.cpp")
  if(NOT srcs)
    return()
  endif()
  add_executable(test_${module} ${srcs})
  target_link_libraries(test_${module} PRIVATE uwb_test_support ${ARG_LINK} GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_options(test_${module} PRIVATE ${UWB_WARNINGS})
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "unit;${module};${ARG_LABELS}")
endfunction()
