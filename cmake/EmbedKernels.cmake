# rtpg_embed_kernels(OUTPUT files...): writes a C++ file defining
#   rtpg::embedded_kernel_files() -> {path relative to kernels/ (include/ for rtpg/*.h), text}
# so the program runs without the source tree. Includes are resolved at program build time
# by host/cl/kernel_source.cpp, which inserts #line directives naming kernels/<path>.
function(rtpg_embed_kernels output)
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output} -DKERNEL_DIR=${CMAKE_SOURCE_DIR}/kernels
            -DINCLUDE_DIR=${CMAKE_SOURCE_DIR}/include
            "-DFILES=${ARGN}" -P ${CMAKE_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    DEPENDS ${ARGN} ${CMAKE_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    COMMENT "Embedding OpenCL kernel sources"
    VERBATIM)
endfunction()
