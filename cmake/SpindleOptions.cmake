# Warnings (as errors on project code) and sanitizer flags, applied per target.

function(spindle_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
    -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual -Werror)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC 12 reports false -Wrestrict positives inside std::string concatenation (GCC bug 105329).
    target_compile_options(${target} PRIVATE -Wno-restrict)
    # wide.hpp's vector types are passed between inline functions of one build only;
    # the note that their ABI depends on AVX being enabled does not concern us.
    target_compile_options(${target} PRIVATE -Wno-psabi)
  endif()
endfunction()

if(SPINDLE_SANITIZE STREQUAL "address")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  # Programs not position independent: UBSan's check records and ASan's global descriptors
  # hold hundreds of thousands of addresses, and a PIE program relocates each one at every
  # start (ctest starts a process per test). The checks are the same either way.
  add_link_options($<$<STREQUAL:$<TARGET_PROPERTY:TYPE>,EXECUTABLE>:-no-pie>)
  # gold (binutils has it beside bfd) links the large instrumented programs faster than bfd.
  add_link_options(-fuse-ld=gold)
elseif(SPINDLE_SANITIZE STREQUAL "thread")
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread -fuse-ld=gold)  # gold: as for ASan above
  add_compile_definitions(SPINDLE_TSAN=1)
elseif(NOT SPINDLE_SANITIZE STREQUAL "")
  message(FATAL_ERROR "SPINDLE_SANITIZE must be '', 'address' or 'thread', got '${SPINDLE_SANITIZE}'")
endif()

# A library layer: include/ is public, src/ private; exported as spindle::<name>.
function(spindle_add_layer name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(spindle_${name} ${ARG_SOURCES})
  add_library(spindle::${name} ALIAS spindle_${name})
  set_target_properties(spindle_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME spindle_${name}
    POSITION_INDEPENDENT_CODE ON)
  target_include_directories(spindle_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(spindle_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  if(SPINDLE_ARCH)
    # Public: Eigen's alignment of fixed-size types in our headers follows the target
    # CPU, so everything that includes them, installed users too, must agree.
    target_compile_options(spindle_${name} PUBLIC -march=${SPINDLE_ARCH})
  endif()
  spindle_target_defaults(spindle_${name})
  if(SPINDLE_PORTABLE_MATH)
    target_compile_options(spindle_${name} PRIVATE -ffp-contract=off)
    # A fixed vector width: Eigen's own SIMD paths (quaternion products, small matrices)
    # follow -march, and an AVX and an SSE2 build would round differently. Public: it also
    # sets Eigen's alignment of the fixed-size types in our headers, which users must share.
    target_compile_definitions(spindle_${name} PUBLIC EIGEN_DONT_VECTORIZE)
  endif()
  install(TARGETS spindle_${name} EXPORT SpindleTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
