# contactrom_add_library(<folder> <sources>...): the library of one source folder,
# target contactrom_<folder> with alias contactrom::<folder> (exported under that
# name), C++17, whose headers are included as "<folder>/x.hpp" from the source tree
# or from <prefix>/include/contactrom once installed.
function(contactrom_add_library folder)
  add_library(contactrom_${folder} ${ARGN})
  add_library(contactrom::${folder} ALIAS contactrom_${folder})
  target_include_directories(contactrom_${folder} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/contactrom>)
  set_target_properties(contactrom_${folder} PROPERTIES EXPORT_NAME ${folder})
  target_compile_features(contactrom_${folder} PUBLIC cxx_std_17)
endfunction()
