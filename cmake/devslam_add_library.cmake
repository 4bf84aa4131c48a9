# Helpers that keep every library's, app's and test's CMake to a few lines.

# Common warnings and options, attached per target (no global flags).
add_library(devslam_options INTERFACE)
target_compile_features(devslam_options INTERFACE cxx_std_17)
target_compile_options(devslam_options INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wno-psabi>)
if(DEVSLAM_SANITIZE)
  target_compile_options(devslam_options INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(devslam_options INTERFACE -fsanitize=address,undefined)
endif()
if(DEVSLAM_SANITIZE_THREAD)
  target_compile_options(devslam_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(devslam_options INTERFACE -fsanitize=thread)
endif()

# Under ThreadSanitizer every program runs OpenCV's loops in the calling thread: OpenCV's own
# thread pool synchronises in uninstrumented code, so TSan would report the loop bodies we
# compile (FastConvolution's) as racing with the thread that started them.
function(devslam_tsan_serial_opencv target)
  if(DEVSLAM_SANITIZE_THREAD)
    target_sources(${target} PRIVATE ${DEVSLAM_SOURCE_DIR}/cmake/TsanSerialOpenCV.cpp)
    target_link_libraries(${target} PRIVATE opencv_core)
  endif()
endfunction()

# devslam_add_library(<name> SOURCES a.cpp ... [DEPS target ...] [OBJECT])
#   -> target devslam_<name>, alias devslam::<name>, public include dir libs/<name>/include
#   OBJECT: build an object library, so that static initializers (MRPT class
#   registration) survive linking into executables that never reference a symbol.
function(devslam_add_library name)
  cmake_parse_arguments(ARG "OBJECT" "" "SOURCES;DEPS" ${ARGN})
  if(ARG_OBJECT)
    add_library(devslam_${name} OBJECT ${ARG_SOURCES})
  else()
    add_library(devslam_${name} STATIC ${ARG_SOURCES})
  endif()
  add_library(devslam::${name} ALIAS devslam_${name})
  target_include_directories(devslam_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_link_libraries(devslam_${name} PUBLIC devslam_options ${ARG_DEPS})
  set_target_properties(devslam_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# devslam_add_app(<exe-name> SOURCES main.cpp ... DEPS devslam::x ...)
function(devslam_add_app name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE devslam_options ${ARG_DEPS})
  target_compile_definitions(${name} PRIVATE DEVSLAM_SOURCE_DIR="${DEVSLAM_SOURCE_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
  devslam_tsan_serial_opencv(${name})
endfunction()

# devslam_add_test(<name> SOURCES t.cpp ... DEPS devslam::x ...)
#   One GoogleTest executable, registered with CTest test by test (gtest_discover_tests).
#   Tests find shipped data through DEVSLAM_SOURCE_DIR and the built apps through DEVSLAM_BIN_DIR.
function(devslam_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  if(DEVSLAM_SANITIZE_THREAD)  # 5-15x slower
    math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * 10")
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE devslam_options ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${DEVSLAM_SOURCE_DIR}/tests/common)  # Scratch.h
  target_compile_definitions(${name} PRIVATE
    DEVSLAM_SOURCE_DIR="${DEVSLAM_SOURCE_DIR}" DEVSLAM_BIN_DIR="${CMAKE_BINARY_DIR}/bin")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  devslam_tsan_serial_opencv(${name})
  include(GoogleTest)
  gtest_discover_tests(${name} WORKING_DIRECTORY ${CMAKE_BINARY_DIR}
    DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT ${ARG_TIMEOUT})
endfunction()
