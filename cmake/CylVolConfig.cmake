# CylVol's CMake package: `find_package(CylVol REQUIRED)` with CylVol_DIR pointing at this
# folder gives the imported target CylVol::cylvol (the static library target/release/libcylvol.a,
# the header include/cylvol.h and the system libraries the Rust static library needs).
#
# By default the library is built with `cargo build --release --lib` by a target that runs on
# every build (cargo is incremental: it rebuilds only when the Rust sources changed), and every
# target linking CylVol::cylvol depends on it. Set CYLVOL_USE_PREBUILT=ON to use an existing
# target/release/libcylvol.a without running cargo (CYLVOL_LIBRARY overrides its path).
#
# Variables set: CylVol_FOUND, CylVol_VERSION (by find_package, from CylVolConfigVersion.cmake,
# which reads Cargo.toml), CylVol_INCLUDE_DIR, CylVol_LIBRARY.

if(NOT TARGET CylVol::cylvol)
  get_filename_component(_cylvol_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)

  option(CYLVOL_USE_PREBUILT "Use an existing libcylvol.a instead of running cargo" OFF)
  set(CYLVOL_LIBRARY "${_cylvol_root}/target/release/${CMAKE_STATIC_LIBRARY_PREFIX}cylvol${CMAKE_STATIC_LIBRARY_SUFFIX}"
      CACHE FILEPATH "The cylvol static library")
  set(CylVol_INCLUDE_DIR "${_cylvol_root}/include")
  set(CylVol_LIBRARY "${CYLVOL_LIBRARY}")

  if(NOT EXISTS "${CylVol_INCLUDE_DIR}/cylvol.h")
    set(CylVol_FOUND FALSE)
    set(CylVol_NOT_FOUND_MESSAGE "cylvol.h not found in ${CylVol_INCLUDE_DIR}")
    return()
  endif()

  if(CYLVOL_USE_PREBUILT)
    if(NOT EXISTS "${CYLVOL_LIBRARY}")
      set(CylVol_FOUND FALSE)
      set(CylVol_NOT_FOUND_MESSAGE
          "CYLVOL_USE_PREBUILT is ON but ${CYLVOL_LIBRARY} does not exist (cargo build --release --lib)")
      return()
    endif()
  else()
    find_program(CYLVOL_CARGO cargo HINTS "$ENV{CARGO_HOME}/bin" "$ENV{HOME}/.cargo/bin")
    if(NOT CYLVOL_CARGO)
      set(CylVol_FOUND FALSE)
      set(CylVol_NOT_FOUND_MESSAGE
          "cargo not found: install Rust, or build libcylvol.a and set CYLVOL_USE_PREBUILT=ON")
      return()
    endif()
    if(NOT TARGET cylvol_cargo_build)
      # Always out of date: cargo decides whether anything needs rebuilding.
      add_custom_target(cylvol_cargo_build
        COMMAND "${CYLVOL_CARGO}" build --release --lib
                --manifest-path "${_cylvol_root}/Cargo.toml"
        WORKING_DIRECTORY "${_cylvol_root}"
        BYPRODUCTS "${CYLVOL_LIBRARY}"
        COMMENT "Building libcylvol.a with cargo (release)"
        USES_TERMINAL
        VERBATIM)
    endif()
  endif()

  # The system libraries the Rust standard library needs in a static link, as
  # `cargo rustc --release --lib --crate-type staticlib -- --print native-static-libs` lists them
  # (Linux: gcc_s util rt pthread m dl c).
  set(_cylvol_system_libs)
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    set(THREADS_PREFER_PTHREAD_FLAG ON)
    find_package(Threads REQUIRED)
    set(_cylvol_system_libs Threads::Threads gcc_s util rt m dl)
  elseif(APPLE)
    set(_cylvol_system_libs "-framework CoreFoundation" "-framework Security" iconv m)
  elseif(WIN32)
    set(_cylvol_system_libs kernel32 advapi32 ntdll userenv ws2_32 bcrypt)
  else()
    set(_cylvol_system_libs pthread m)
  endif()

  add_library(CylVol::cylvol STATIC IMPORTED GLOBAL)
  set_target_properties(CylVol::cylvol PROPERTIES
    IMPORTED_LOCATION "${CYLVOL_LIBRARY}"
    IMPORTED_LINK_INTERFACE_LANGUAGES "C"
    INTERFACE_INCLUDE_DIRECTORIES "${CylVol_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${_cylvol_system_libs}")
  if(TARGET cylvol_cargo_build)
    add_dependencies(CylVol::cylvol cylvol_cargo_build)
  endif()

  unset(_cylvol_system_libs)
  unset(_cylvol_root)
endif()

set(CylVol_FOUND TRUE)
