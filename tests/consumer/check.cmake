cmake_minimum_required(VERSION 3.22)
# ctest: install the build tree to a scratch prefix, then configure and build tests/consumer
# against it. -DBUILD=<omnivert build dir> -DSRC=<source dir> -DWORK=<scratch dir>
file(REMOVE_RECURSE "${WORK}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD}" --prefix "${WORK}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "install failed (${rc})")
endif()
# Only public headers are installed: no header of src/ may be among them.
file(GLOB_RECURSE installed RELATIVE "${WORK}/prefix/include" "${WORK}/prefix/include/*")
file(GLOB_RECURSE private RELATIVE "${SRC}/src" "${SRC}/src/*.hpp")
foreach(p IN LISTS private)
  if("omnivert/${p}" IN_LIST installed)
    message(FATAL_ERROR "private header installed: ${p}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${SRC}/tests/consumer" -B "${WORK}/build" -G Ninja
                        "-DCMAKE_PREFIX_PATH=${WORK}/prefix" "-DOMNIVERT_README=${SRC}/README.md"
                        -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK}/build" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed (${rc})")
endif()
# omnivert::calib must not bring OpenCV: its link line (Ninja's) names no opencv library.
file(READ "${WORK}/build/build.ninja" ninja)
string(FIND "${ninja}" "build calib_only:" at)
string(SUBSTRING "${ninja}" ${at} -1 rest)
string(REGEX MATCH "LINK_LIBRARIES = [^\n]*" link "${rest}")
if(at EQUAL -1 OR NOT link MATCHES "omnivert_calib")
  message(FATAL_ERROR "no link line of calib_only in ${WORK}/build/build.ninja")
endif()
if(link MATCHES "opencv")
  message(FATAL_ERROR "omnivert::calib links OpenCV: ${link}")
endif()
message(STATUS "consumer built against ${WORK}/prefix: ${installed}")
