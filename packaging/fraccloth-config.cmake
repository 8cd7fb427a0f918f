# find_package(fraccloth) support: defines the imported target fraccloth::fraccloth (the
# shared library with its include directory; C and C++ via fraccloth.h / fraccloth.hpp).
get_filename_component(_fraccloth_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)
if(NOT TARGET fraccloth::fraccloth)
  add_library(fraccloth::fraccloth SHARED IMPORTED)
  set_target_properties(fraccloth::fraccloth PROPERTIES
    IMPORTED_LOCATION "${_fraccloth_prefix}/lib/libfraccloth.so"
    INTERFACE_INCLUDE_DIRECTORIES "${_fraccloth_prefix}/include")
  if(NOT EXISTS "${_fraccloth_prefix}/lib/libfraccloth.so")
    set(fraccloth_FOUND FALSE)
    set(fraccloth_NOT_FOUND_MESSAGE "libfraccloth.so not found under ${_fraccloth_prefix}/lib")
  endif()
endif()
unset(_fraccloth_prefix)
