# ctest install.example: installs the build tree into a temporary prefix, checks
# that nothing installed points into the source or build folder, runs the
# installed CLI (which must find its data relative to the prefix), then configures,
# builds and runs examples/cpp against the installed package, then builds
# tests/install/consumer (every installed header as <contactrom/...>, no HDF5).
# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DWORK_DIR=... -DGENERATOR=... -DHEADERS=contactrom/core/a.hpp,...
#       [-DSANITIZE=ON] -P run_install_test.cmake
# HEADERS lists the installed headers (tests/CMakeLists.txt takes them from the libraries).
#
# SANITIZE=ON (a CONTACTROM_SANITIZE build): GCC writes the source paths of
# AddressSanitizer's and UBSan's diagnostics into the objects without applying
# -ffile-prefix-map, so the installed libraries and programs name the source folder
# there; the path check then covers the installed text files (CMake package files,
# headers, problem files), and says so. The example is built with the sanitizer
# flags, as the installed static libraries need their runtime.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

function(expect text pattern what)
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "${what}: expected /${pattern}/ in:\n${text}")
  endif()
endfunction()

# The installed copy must find everything by itself.
unset(ENV{CONTACTROM_PROBLEM_DIR})
unset(ENV{CONTACTROM_MESH_DIR})
set(prefix ${WORK_DIR}/prefix)

file(REMOVE_RECURSE ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

set(grep_options -r -l -F)
set(example_flags "")
if(SANITIZE)
  list(APPEND grep_options -I)  # binary files skipped (see above)
  message(STATUS "sanitizer build: installed binaries carry the sanitizers' source paths; path check on text files only")
  set(example_flags -DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
foreach(dir ${SOURCE_DIR} ${BUILD_DIR})
  get_filename_component(real ${dir} REALPATH)
  foreach(path ${dir} ${real})
    execute_process(COMMAND grep ${grep_options} ${path} ${prefix} RESULT_VARIABLE rc OUTPUT_VARIABLE hits)
    if(NOT rc EQUAL 1)
      message(FATAL_ERROR "installed files mention ${path}:\n${hits}")
    endif()
  endforeach()
endforeach()

run(${prefix}/bin/contactrom problems)
expect("${out}" "${prefix}/share/contactrom/problems" "installed CLI's problem folder")
run(${prefix}/bin/contactrom online --help)
expect("${out}" "cpg_tolerance" "online --help lists the options of cpg")
run(${prefix}/bin/contactrom fom --problem hertz --param 0.1 --json)
expect("${out}" "\"iterations\"" "installed CLI solves hertz")

run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/cpp -B ${WORK_DIR}/example -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} ${example_flags})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/example -j 2)
# The example is not under the prefix: it finds the shipped problem by name in the
# installed package (as the installed problem file, below).
run(${WORK_DIR}/example/hertz_rom hertz 0.1275)
expect("${out}" "FOM: success" "the example finds the shipped hertz in the installed package")
run(${WORK_DIR}/example/hertz_rom ${prefix}/share/contactrom/problems/hertz.toml 0.1275)
message(STATUS "${out}")
expect("${out}" "FOM: success" "FOM status")
foreach(method greedy cpg)
  expect("${out}" "ROM ${method}: success, contact force [^,]+, primal H1 error ([^,]+), dual L2 error ([^,]+)," "ROM ${method}")
  string(REGEX MATCH "ROM ${method}: success, contact force [^,]+, primal H1 error ([^,]+), dual L2 error ([^,]+),"
         line "${out}")
  # hertz from 12 snapshots, query between two of them: errors of a working ROM.
  if(NOT CMAKE_MATCH_1 LESS 1e-2 OR NOT CMAKE_MATCH_2 LESS 0.2)
    message(FATAL_ERROR "ROM ${method}: errors ${CMAKE_MATCH_1} (primal) ${CMAKE_MATCH_2} (dual) too large")
  endif()
endforeach()

# Every installed header, included as <contactrom/...> by a program that finds only
# contactrom (not HDF5, a private dependency: no installed header may include it).
execute_process(COMMAND grep -r -l "include <hdf5" ${prefix}/include RESULT_VARIABLE rc OUTPUT_VARIABLE hits)
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "installed headers include <hdf5.h>:\n${hits}")
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${WORK_DIR}/consumer -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DCONTACTROM_HEADERS=${HEADERS} ${example_flags})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer -j 2)
run(${WORK_DIR}/consumer/all_headers)
expect("${out}" "contactrom [0-9]+\\.[0-9]+\\.[0-9]+, [0-9]+ headers" "the program including every installed header")
file(REMOVE_RECURSE ${WORK_DIR})
