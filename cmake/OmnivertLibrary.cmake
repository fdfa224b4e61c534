# omnivert_add_library(STAGE SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
#
# One library per pipeline stage: target omnivert_<stage>, alias and export name
# omnivert::<stage>. Public headers are include/omnivert/<stage>/ (installed); private headers
# live beside the sources in src/<stage>/ and are included as "<stage>/<name>.hpp" from the
# build tree only (never installed). A stage lists as PUBLIC_DEPS the stages below it that its
# public headers use; scripts/check-layering checks that no stage includes a stage above it.
function(omnivert_add_library stage)
  cmake_parse_arguments(A "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target omnivert_${stage})
  add_library(${target} ${A_SOURCES})
  add_library(omnivert::${stage} ALIAS ${target})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target}
    PUBLIC ${A_PUBLIC_DEPS}
    PRIVATE ${A_PRIVATE_DEPS})
  target_compile_options(${target} PRIVATE ${OMNIVERT_WARNING_FLAGS})
  # Maths functions need not set errno, and floating-point exceptions are not traps (nothing
  # here reads errno or the exception flags; clang's default): sqrt is then one instruction,
  # and per-pixel loops with comparisons and selects vectorise. The values computed are the
  # same IEEE results either way.
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-fno-math-errno -fno-trapping-math>)
  set_target_properties(${target} PROPERTIES
    POSITION_INDEPENDENT_CODE ON
    EXPORT_NAME ${stage})
  set_property(GLOBAL APPEND PROPERTY OMNIVERT_STAGE_TARGETS ${target})
endfunction()
