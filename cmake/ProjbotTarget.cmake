# One place for the compile options every Projbot target shares.
function(projbot_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion -Wnon-virtual-dtor)
  if(PROJBOT_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(PROJBOT_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${PROJBOT_SANITIZE} -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=${PROJBOT_SANITIZE})
    # Under ASan, Eigen stops trusting malloc's 16-byte alignment and over-allocates by hand, while the
    # packaged PCL (no sanitizer) frees Eigen-allocated clouds with plain free: the two must agree.
    target_compile_definitions(${target} PUBLIC EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
endfunction()

# A module library: projbot::<name> from <name>/src/*.cpp with public headers in <name>/include.
function(projbot_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(projbot_${name} ${ARG_SOURCES})
  add_library(projbot::${name} ALIAS projbot_${name})
  target_include_directories(projbot_${name} PUBLIC "${CMAKE_CURRENT_SOURCE_DIR}/include")
  target_link_libraries(projbot_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  projbot_target_options(projbot_${name})
endfunction()
