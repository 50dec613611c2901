# redres_hot_sources_apart(<sources>...): a source that defines a function of the per-step path (marked REDRES_HOT,
# redres/common/hot.hpp) is compiled on its own, never in a unity batch. In a batch, GCC sees a translation unit many
# times larger and inlines less within it (the QP builder's bound intersection, Eigen's small assignments became
# calls), which cost the paper's step about 5 % (docs/performance.md). The other sources keep the batches' build time. Read when CMake configures.
function(redres_hot_sources_apart)
  foreach(source IN LISTS ARGN)
    file(READ ${source} text)
    string(FIND "${text}" "REDRES_HOT " at)
    if(NOT at EQUAL -1)
      set_source_files_properties(${source} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
    endif()
  endforeach()
endfunction()
