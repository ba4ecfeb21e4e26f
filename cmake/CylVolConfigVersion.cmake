# Version file of the CylVol package: the version is the crate's, read from Cargo.toml. A
# request is compatible with a version that is not older and has the same major version
# (for 0.x versions: the same minor version, as Cargo's rules have it).
file(STRINGS "${CMAKE_CURRENT_LIST_DIR}/../Cargo.toml" _cylvol_version_line
     REGEX "^version = \"[0-9]+\\.[0-9]+\\.[0-9]+.*\"" LIMIT_COUNT 1)
string(REGEX REPLACE "^version = \"([0-9]+\\.[0-9]+\\.[0-9]+).*" "\\1" PACKAGE_VERSION
       "${_cylvol_version_line}")
unset(_cylvol_version_line)

set(PACKAGE_VERSION_COMPATIBLE FALSE)
if(NOT PACKAGE_FIND_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
elseif(NOT PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)
  string(REGEX MATCHALL "[0-9]+" _cylvol_have "${PACKAGE_VERSION}")
  list(GET _cylvol_have 0 _cylvol_major)
  list(GET _cylvol_have 1 _cylvol_minor)
  if(_cylvol_major STREQUAL "0")
    if(PACKAGE_FIND_VERSION_MAJOR STREQUAL "0" AND PACKAGE_FIND_VERSION_MINOR STREQUAL _cylvol_minor)
      set(PACKAGE_VERSION_COMPATIBLE TRUE)
    endif()
  elseif(PACKAGE_FIND_VERSION_MAJOR STREQUAL _cylvol_major)
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
  endif()
  unset(_cylvol_have)
  unset(_cylvol_major)
  unset(_cylvol_minor)
endif()
if(PACKAGE_FIND_VERSION AND PACKAGE_FIND_VERSION VERSION_EQUAL PACKAGE_VERSION)
  set(PACKAGE_VERSION_EXACT TRUE)
endif()
