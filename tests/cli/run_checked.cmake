# run(<command> <args>...): runs a command and stops the calling test script, with the command's output, when it
# fails; LAST_OUTPUT then holds its standard output. RUN_FAILURE_NOTE, if set, is added to the failure message.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}\n${RUN_FAILURE_NOTE}")
  endif()
  set(LAST_OUTPUT "${out}" PARENT_SCOPE)
endfunction()
