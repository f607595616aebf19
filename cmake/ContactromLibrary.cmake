# contactrom_add_library(<folder> SOURCES <a.cpp>... PUBLIC_HEADERS <a.hpp>... [PRIVATE_HEADERS <b.hpp>...]):
# the library of one source folder, target contactrom_<folder> with alias
# contactrom::<folder> (exported under that name), C++17, whose headers are included
# as <contactrom/<folder>/x.hpp> from the build tree and from <prefix>/include. Files are named relative
# to the folder, each listed explicitly. PUBLIC_HEADERS are installed to
# <prefix>/include/contactrom/<folder>/ (ContactromInstall.cmake) and must include
# only public headers and public dependencies; PRIVATE_HEADERS (those that include
# a private dependency such as <hdf5.h>, or internals) are not installed. Every
# header of the folder is in one list or the other.
function(contactrom_add_library folder)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "SOURCES;PUBLIC_HEADERS;PRIVATE_HEADERS")
  set(dir ${CMAKE_CURRENT_SOURCE_DIR})
  list(TRANSFORM arg_SOURCES PREPEND ${dir}/)
  list(TRANSFORM arg_PUBLIC_HEADERS PREPEND ${dir}/ OUTPUT_VARIABLE public)
  list(TRANSFORM arg_PRIVATE_HEADERS PREPEND ${dir}/ OUTPUT_VARIABLE private)
  add_library(contactrom_${folder} ${arg_SOURCES} ${public} ${private})
  add_library(contactrom::${folder} ALIAS contactrom_${folder})
  # Headers are included as <contactrom/<folder>/x.hpp>, in the tree as once installed:
  # the build tree's include/contactrom/<folder> is a link to the folder.
  file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/include/contactrom)
  file(CREATE_LINK ${dir} ${PROJECT_BINARY_DIR}/include/contactrom/${folder} SYMBOLIC)
  target_include_directories(contactrom_${folder} PUBLIC $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  set_target_properties(contactrom_${folder} PROPERTIES EXPORT_NAME ${folder}
                        CONTACTROM_PUBLIC_HEADERS "${public}")
  target_compile_features(contactrom_${folder} PUBLIC cxx_std_17)
endfunction()
