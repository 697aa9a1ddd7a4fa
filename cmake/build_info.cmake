# fovea — writes the build-time provenance header (fv_build_info.h) that src/core/provenance.c
# compiles in. Run by the fv_build_info target on every build (cmake -P), so a new commit or an
# edit is picked up without reconfiguring; configure_file rewrites the header only when its text
# changes, so an unchanged tree recompiles nothing and a new commit recompiles one file.
#
# In:  SRC (source tree), OUT (header path), IN (template).
# A source tree that is not its own git work tree (a tarball, even one unpacked inside another
# repository) records the commit as "unknown" and the dirty flag as unknown (-1).
set(FV_GIT_COMMIT "unknown")
set(FV_GIT_DIRTY -1)
find_program(FV_GIT git)
if(FV_GIT)
  execute_process(COMMAND ${FV_GIT} -C ${SRC} rev-parse --show-toplevel OUTPUT_VARIABLE top RESULT_VARIABLE rc
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(rc EQUAL 0)
    get_filename_component(top "${top}" REALPATH)
    get_filename_component(src_real "${SRC}" REALPATH)
  endif()
  if(rc EQUAL 0 AND top STREQUAL src_real)
    execute_process(COMMAND ${FV_GIT} -C ${SRC} rev-parse HEAD OUTPUT_VARIABLE commit RESULT_VARIABLE rc
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(rc EQUAL 0 AND commit MATCHES "^[0-9a-f]+$")
      set(FV_GIT_COMMIT "${commit}")
      # Tracked files only: build folders and scratch files do not make a build "dirty".
      execute_process(COMMAND ${FV_GIT} -C ${SRC} status --porcelain --untracked-files=no OUTPUT_VARIABLE changes
                      RESULT_VARIABLE rc ERROR_QUIET)
      if(rc EQUAL 0)
        if(changes STREQUAL "")
          set(FV_GIT_DIRTY 0)
        else()
          set(FV_GIT_DIRTY 1)
        endif()
      endif()
    endif()
  endif()
endif()
configure_file(${IN} ${OUT} @ONLY)
