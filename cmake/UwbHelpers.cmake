# Helpers shared by every module: warnings, sanitizers, one static library per concept folder.

# Developer builds print warnings (-Wshadow=local is GCC's; clang has no 'local' variant). User builds
# (UWB_DEV_WARNINGS=OFF, scripts/demo.sh) print none: GCC 12 reports false positives inside Eigen and std::string.
if(UWB_DEV_WARNINGS)
  set(UWB_WARNINGS -Wall -Wextra -Wpedantic -Wnon-virtual-dtor $<$<CXX_COMPILER_ID:GNU>:-Wshadow=local>)
  # The sanitizer build (scripts/test.sh): GCC 12 reports -Wmaybe-uninitialized / -Wuninitialized false positives
  # in its own avx512fintrin.h wherever Eigen's packet code is inlined into our functions under -march=native with
  # ASan's instrumentation (about 2 500 lines, none in our code). The header is already a system header, so the
  # warning cannot be silenced where the header is included; these two warnings are off for that build only. The
  # Release build keeps them.
  if(UWB_SANITIZE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    list(APPEND UWB_WARNINGS -Wno-maybe-uninitialized -Wno-uninitialized)
  endif()
  # GCC 12 at -O2 and above: -Wrestrict false positive inside libstdc++'s char_traits.h for `"literal" + std::string`
  # (GCC bug 105329, fixed in GCC 13), e.g. the parameter names "p" + std::to_string(p) + ... of gp/kernels.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    list(APPEND UWB_WARNINGS -Wno-restrict)
  endif()
  # -DUWB_WERROR=ON (developers): a warning in the project's own targets fails the build. Third-party code is compiled
  # only through its headers, which are system includes (imported targets), so this covers our code alone.
  if(UWB_WERROR)
    list(APPEND UWB_WARNINGS -Werror)
  endif()
else()
  set(UWB_WARNINGS -w)
  add_compile_options(-w)
  add_link_options(-w)  # link-time optimization compiles again at the link
endif()
if(UWB_SANITIZE AND UWB_TSAN)
  message(FATAL_ERROR "UWB_SANITIZE (ASan/UBSan) and UWB_TSAN cannot be combined; use two build folders")
endif()
# UBSan without its per-access pointer checks (alignment, null, object-size, pointer-overflow): in Eigen's inlined
# kernels they instrument every load and store and make the build about 1.6x slower to compile; ASan reports the
# null and out-of-bounds accesses they would, and a misaligned Eigen packet load faults by itself. The arithmetic,
# enum/bool, vptr, return and bounds checks stay.
if(UWB_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=alignment,null,object-size,pointer-overflow
                      -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
if(UWB_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
# Fuzzing (fuzz/): every library is instrumented for coverage; the harnesses add libFuzzer's main. Needs clang.
if(UWB_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "UWB_FUZZ needs clang (e.g. CXX=clang++-14); the compiler is ${CMAKE_CXX_COMPILER_ID}")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
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
