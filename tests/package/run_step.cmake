# Runs one command of a package test and stops the test with its output when it fails.
function(sf_run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok")
  set(SF_STEP_OUTPUT "${out}" PARENT_SCOPE)
endfunction()
