# galpha_fortran_module_dir(VAR): the directory name for this compiler's .mod files. Modules
# are readable only by compilers that write the same module format, so they go where that
# format is named: gfortran-mod-<version> (the version gfortran writes into every .mod,
# read from a probe module; Debian's dh_fortran_mod uses the same names), else
# <compiler id>-<compiler version>.
function(galpha_fortran_module_dir var)
  set(dir "${CMAKE_Fortran_COMPILER_ID}-${CMAKE_Fortran_COMPILER_VERSION}")
  if(CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
    set(probe ${PROJECT_BINARY_DIR}/CMakeFiles/fortran_module_probe)
    file(MAKE_DIRECTORY ${probe})
    file(WRITE ${probe}/probe.f90 "module galpha_probe\nend module galpha_probe\n")
    execute_process(COMMAND ${CMAKE_Fortran_COMPILER} -c probe.f90 WORKING_DIRECTORY ${probe}
                    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
    if(rc EQUAL 0)
      execute_process(COMMAND gzip -dc galpha_probe.mod WORKING_DIRECTORY ${probe}
                      OUTPUT_VARIABLE head ERROR_QUIET)
      if(head MATCHES "GFORTRAN module version '([0-9]+)'")
        set(dir "gfortran-mod-${CMAKE_MATCH_1}")
      endif()
    endif()
  endif()
  set(${var} ${dir} PARENT_SCOPE)
endfunction()
