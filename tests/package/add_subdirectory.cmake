# ctest Package.AddSubdirectory: a parent project configures and builds shadowfilter's core
# library through add_subdirectory, and runs a consumer of it.
#   cmake -DSOURCE=<shadowfilter source> -DWORK=<scratch dir> -DGENERATOR=<generator> -P add_subdirectory.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)
file(REMOVE_RECURSE ${WORK})
sf_run_step("configure the parent project"
  ${CMAKE_COMMAND} -S ${SOURCE}/tests/package/subdirectory -B ${WORK} -G ${GENERATOR}
  -DCMAKE_BUILD_TYPE=Release -DSF_SOURCE=${SOURCE})
sf_run_step("build the core library and the consumer" ${CMAKE_COMMAND} --build ${WORK} -j 2)
sf_run_step("run the consumer" ${WORK}/consumer)
message(STATUS "${SF_STEP_OUTPUT}")
