# Tests cmake/provenance.cmake on a repository of its own: a clean checkout gives its commit, a
# changed tracked file "-dirty", an untracked file nothing, a directory outside git "unknown", and
# an unchanged tree leaves the header as it was (nothing recompiles).
# Usage: cmake -DSCRIPT=cmake/provenance.cmake -DWORK=DIR -P test_provenance.cmake
if(NOT SCRIPT OR NOT WORK)
  message(FATAL_ERROR "test_provenance: SCRIPT and WORK are required")
endif()
file(REMOVE_RECURSE "${WORK}")
set(repo "${WORK}/repo")
file(MAKE_DIRECTORY "${repo}" "${WORK}/nogit")
set(header "${WORK}/tippe_git_commit.h")

function(git)
  execute_process(COMMAND git -c user.email=test@example.invalid -c user.name=test ${ARGN}
                  WORKING_DIRECTORY "${repo}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "git ${ARGN}: ${err}")
  endif()
  set(git_out "${out}" PARENT_SCOPE)
endfunction()
# Runs the script on DIR (outside git: no repository above WORK is searched) and reads the commit.
function(stamp dir)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "GIT_CEILING_DIRECTORIES=${WORK}"
                  ${CMAKE_COMMAND} -DSOURCE_DIR=${dir} -DOUTPUT=${header} -P ${SCRIPT} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "provenance.cmake failed on ${dir}")
  endif()
  file(STRINGS "${header}" line REGEX "^#define TIPPE_GIT_COMMIT ")
  string(REGEX REPLACE "^#define TIPPE_GIT_COMMIT \"(.*)\"$" "\\1" commit "${line}")
  set(stamped "${commit}" PARENT_SCOPE)
endfunction()
function(expect what got want)
  if(NOT got STREQUAL want)
    message(FATAL_ERROR "${what}: got \"${got}\", want \"${want}\"")
  endif()
  message(STATUS "${what}: ${got}")
endfunction()

git(init -q)
file(WRITE "${repo}/a.txt" "one\n")
git(add a.txt)
git(commit -q -m first)
git(rev-parse --short=12 HEAD)
set(head "${git_out}")

stamp("${repo}")
expect("a clean checkout" "${stamped}" "${head}")
file(TIMESTAMP "${header}" before "%s")
execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 1.1)
stamp("${repo}")
file(TIMESTAMP "${header}" after "%s")
expect("the header's time when nothing changed" "${after}" "${before}")

file(WRITE "${repo}/b.txt" "untracked\n")
stamp("${repo}")
expect("an untracked file" "${stamped}" "${head}")

file(WRITE "${repo}/a.txt" "two\n")
stamp("${repo}")
expect("a changed tracked file" "${stamped}" "${head}-dirty")

git(commit -q -am second)
git(rev-parse --short=12 HEAD)
stamp("${repo}")
expect("a new commit" "${stamped}" "${git_out}")

stamp("${WORK}/nogit")
expect("outside git" "${stamped}" "unknown")
