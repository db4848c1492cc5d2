# Embeds an OpenCL C file (with the project headers it #includes inlined) into a generated C++
# header, so the library never reads kernels from disk at run time.
#
#   fogcl_embed_kernel(TARGET <tgt> SOURCE <file.cl> SYMBOL <name> DEPENDS <headers...>)
#
# produces <binary dir>/generated/fogcl_kernels/<name>.h defining
#   inline constexpr char <name>[] = R"fogcl_cl(...)fogcl_cl";
# and adds the folder to <tgt>'s private include path. Editing the .cl or any listed header
# regenerates it.
set(FOGCL_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_kernel.cmake)

function(fogcl_embed_kernel)
  cmake_parse_arguments(ARG "" "TARGET;SOURCE;SYMBOL" "DEPENDS" ${ARGN})
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/generated/fogcl_kernels)
  set(out ${out_dir}/${ARG_SYMBOL}.h)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DSOURCE=${ARG_SOURCE} -DOUTPUT=${out} -DSYMBOL=${ARG_SYMBOL}
            -P ${FOGCL_EMBED_SCRIPT}
    DEPENDS ${ARG_SOURCE} ${ARG_DEPENDS} ${FOGCL_EMBED_SCRIPT}
    COMMENT "Embedding OpenCL kernel ${ARG_SOURCE}"
    VERBATIM)
  target_sources(${ARG_TARGET} PRIVATE ${out})
  target_include_directories(${ARG_TARGET} PRIVATE ${out_dir})
endfunction()

# White-box tests and benchmarks that build a kernel themselves include the library's own
# generated headers: the symbols are inline variables, so a second embedding of the same kernel
# with fewer dependencies would be a second definition that the linker may pick, stale (the
# bench's deferred_fog_cl once missed an edit of fog_cpu_blocks.h and replaced the library's).
#   fogcl_use_embedded_kernels(TARGET <tgt> FROM <library target that embeds them>)
function(fogcl_use_embedded_kernels)
  cmake_parse_arguments(ARG "" "TARGET;FROM" "" ${ARGN})
  get_target_property(from_dir ${ARG_FROM} BINARY_DIR)
  target_include_directories(${ARG_TARGET} PRIVATE ${from_dir}/generated/fogcl_kernels)
  add_dependencies(${ARG_TARGET} ${ARG_FROM})
endfunction()
