# ctest Package.AddSubdirectory: a parent project configures and builds shadowfilter's core
# library through add_subdirectory, static and shared (SF_SHARED), and runs a consumer of each.
# Built unoptimised (build type None: no flags): what is checked is the build's plumbing, and -O0
# compiles in three quarters of Release's time.
#   cmake -DSOURCE=<shadowfilter source> -DWORK=<scratch dir> -DGENERATOR=<generator> -P add_subdirectory.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)
file(REMOVE_RECURSE ${WORK})
foreach(shared OFF ON)
  set(dir ${WORK}/shared-${shared})
  sf_run_step("configure the parent project (SF_SHARED ${shared})"
    ${CMAKE_COMMAND} -S ${SOURCE}/tests/package/subdirectory -B ${dir} -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=None -DSF_SOURCE=${SOURCE} -DSF_SHARED=${shared})
  sf_run_step("build the core library and the consumer (SF_SHARED ${shared})" ${CMAKE_COMMAND} --build ${dir} -j 2)
  sf_run_step("run the consumer (SF_SHARED ${shared})" ${dir}/consumer)
  message(STATUS "${SF_STEP_OUTPUT}")
endforeach()

# The shared library exports the sf:: API alone: no opencl.hpp (cl::) or other C++ symbol.
find_program(NM nm REQUIRED)
file(GLOB so ${WORK}/shared-ON/shadowfilter/libshadowfilter.so.*.*)
sf_run_step("list the shared library's exports" ${NM} -D -C --defined-only ${so})
string(REPLACE "\n" ";" exports "${SF_STEP_OUTPUT}")
set(foreign "")
foreach(line IN LISTS exports)
  if(line MATCHES " [A-Za-z] (.*)$")
    set(sym "${CMAKE_MATCH_1}")
    if(NOT sym MATCHES "sf::" AND NOT sym MATCHES "^(_init|_fini|_edata|_end|__bss_start)$")
      list(APPEND foreign "${sym}")
    endif()
  endif()
endforeach()
list(LENGTH exports n)
if(foreign)
  message(FATAL_ERROR "libshadowfilter.so exports more than sf::\n${foreign}")
endif()
message(STATUS "libshadowfilter.so: ${n} exported symbols, every one in sf::")
