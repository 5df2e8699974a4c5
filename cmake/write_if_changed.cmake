# write_if_changed(PATH TEXT): writes TEXT to PATH only when the file does not already hold it,
# so that a generated source rebuilds what includes it only when it changes. Included by the
# -P scripts that generate sources at every build.
function(write_if_changed path text)
  set(old "")
  if(EXISTS "${path}")
    file(READ "${path}" old)
  endif()
  if(NOT "${old}" STREQUAL "${text}")
    file(WRITE "${path}" "${text}")
  endif()
endfunction()
