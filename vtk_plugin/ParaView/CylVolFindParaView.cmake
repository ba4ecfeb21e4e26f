# cylvol_find_paraview(): find_package(ParaView REQUIRED) for a ParaView installed without its
# Python modules, whose files the plugin's build takes from a folder they are unpacked in.
#
# ParaView's CMake package describes its whole installation. Loading it, CMake's generated
# export files check that every file an imported target names exists, and stop with "The
# imported target ... references the file ... but this file does not exist" otherwise. On
# Debian 12, three export sets of paraview-dev name files of the package python3-paraview:
#
#   vtk/VTKPython-targets.cmake     <prefix>/lib/python3/dist-packages/vtkmodules/vtk*.so
#                                   (ParaView's VTK's Python modules, 122 files)
#   ParaViewPython-targets.cmake    <prefix>/lib/python3/dist-packages/paraview/modules/*.so
#   ParaViewTools-targets.cmake     <prefix>/bin/pvpython
#
# python3-paraview cannot be installed beside Debian's python3-vtk9 (both own
# dist-packages/vtkmodules), and a plugin needs none of those targets. So, before
# find_package, this declares every target of an export set whose files are missing as an
# empty interface target: the export file then finds all of its targets defined and returns
# before its checks (CMake's generated code does so whenever a package is loaded twice).
# Export sets whose files are all present are left to the package. Nothing is changed on the
# system.
#
# The same package also holds the wrapping hierarchy files of every VTK and ParaView module
# (<prefix>/lib/<arch>/vtk/hierarchy/ParaView/*-hierarchy.txt), which wrapping the plugin's
# classes for ParaView's server manager reads. When they are not installed, they are taken
# from CYLVOL_PARAVIEW_PYTHON_ROOT, a folder python3-paraview's package is unpacked in
# (`apt-get download python3-paraview && dpkg -x python3-paraview_*.deb ROOT`, which also
# gives pvbatch and pvpython their Python: PYTHONPATH=ROOT/usr/lib/python3/dist-packages).
#
# The package is looked for in ParaView_DIR, else under CMAKE_PREFIX_PATH and the system
# prefixes (lib/cmake/paraview-* and lib/<arch>/cmake/paraview-*).

function (_cylvol_paraview_config_dir out)
  if (ParaView_DIR AND EXISTS "${ParaView_DIR}/paraview-config.cmake")
    set("${out}" "${ParaView_DIR}" PARENT_SCOPE)
    return ()
  endif ()
  foreach (prefix IN LISTS CMAKE_PREFIX_PATH CMAKE_SYSTEM_PREFIX_PATH)
    file(GLOB configs
      "${prefix}/lib/cmake/paraview-*/paraview-config.cmake"
      "${prefix}/lib/*/cmake/paraview-*/paraview-config.cmake")
    if (configs)
      list(GET configs 0 config)
      get_filename_component(dir "${config}" DIRECTORY)
      set("${out}" "${dir}" PARENT_SCOPE)
      return ()
    endif ()
  endforeach ()
  set("${out}" "" PARENT_SCOPE)
endfunction ()

# The installation prefix an export file computes: its folder, up as many levels as the file
# climbs.
function (_cylvol_export_prefix targets_file out)
  file(STRINGS "${targets_file}" climbs
    REGEX "^get_filename_component\\(_IMPORT_PREFIX \"\\\${_IMPORT_PREFIX}\" PATH\\)$")
  get_filename_component(prefix "${targets_file}" DIRECTORY)
  foreach (climb IN LISTS climbs)
    get_filename_component(prefix "${prefix}" DIRECTORY)
  endforeach ()
  set("${out}" "${prefix}" PARENT_SCOPE)
endfunction ()

# The files an export set's configuration files say its targets need, missing ones only.
function (_cylvol_export_missing_files targets_file out)
  _cylvol_export_prefix("${targets_file}" prefix)
  string(REGEX REPLACE "\\.cmake$" "-*.cmake" pattern "${targets_file}")
  file(GLOB config_files "${pattern}")
  set(missing)
  foreach (config_file IN LISTS config_files)
    file(STRINGS "${config_file}" lines REGEX "^list\\(APPEND _cmake_import_check_files_for_")
    foreach (line IN LISTS lines)
      string(REGEX MATCHALL "\"[^\"]*\"" files "${line}")
      foreach (file IN LISTS files)
        string(REPLACE "\"" "" file "${file}")
        string(REPLACE "\${_IMPORT_PREFIX}" "${prefix}" file "${file}")
        if (NOT EXISTS "${file}")
          list(APPEND missing "${file}")
        endif ()
      endforeach ()
    endforeach ()
  endforeach ()
  set("${out}" "${missing}" PARENT_SCOPE)
endfunction ()

function (_cylvol_declare_export_targets targets_file)
  file(STRINGS "${targets_file}" line REGEX "^foreach\\(_cmake_expected_target IN ITEMS ")
  string(REGEX REPLACE "^foreach\\(_cmake_expected_target IN ITEMS (.*)\\)$" "\\1" names "${line}")
  separate_arguments(names)
  foreach (name IN LISTS names)
    if (NOT TARGET "${name}")
      add_library("${name}" INTERFACE IMPORTED GLOBAL)
    endif ()
  endforeach ()
endfunction ()

macro (cylvol_find_paraview)
  _cylvol_paraview_config_dir(_cylvol_paraview_dir)
  if (_cylvol_paraview_dir)
    file(GLOB _cylvol_paraview_exports
      "${_cylvol_paraview_dir}/*-targets.cmake" "${_cylvol_paraview_dir}/vtk/*-targets.cmake")
    foreach (_cylvol_export IN LISTS _cylvol_paraview_exports)
      _cylvol_export_missing_files("${_cylvol_export}" _cylvol_missing)
      if (_cylvol_missing)
        list(LENGTH _cylvol_missing _cylvol_missing_count)
        get_filename_component(_cylvol_export_name "${_cylvol_export}" NAME)
        message(STATUS "ParaView: ${_cylvol_export_name} names ${_cylvol_missing_count} files "
          "that are not installed (ParaView's Python, package python3-paraview); its targets "
          "are declared empty, as this build uses none of them")
        _cylvol_declare_export_targets("${_cylvol_export}")
      endif ()
    endforeach ()
    set(ParaView_DIR "${_cylvol_paraview_dir}" CACHE PATH "Where paraview-config.cmake is")
  endif ()
  find_package(ParaView REQUIRED)
  _cylvol_locate_hierarchies()
endmacro ()

# Points every imported module whose wrapping hierarchy file is not installed at the same
# file under CYLVOL_PARAVIEW_PYTHON_ROOT.
function (_cylvol_locate_hierarchies)
  set(CYLVOL_PARAVIEW_PYTHON_ROOT "" CACHE PATH
    "A folder python3-paraview is unpacked in (dpkg -x), for the wrapping hierarchy files")
  get_property(targets DIRECTORY PROPERTY IMPORTED_TARGETS)
  set(missing 0)
  foreach (target IN LISTS targets)
    get_property(hierarchy TARGET "${target}" PROPERTY INTERFACE_vtk_module_hierarchy)
    if (NOT hierarchy OR EXISTS "${hierarchy}")
      continue ()
    endif ()
    if (CYLVOL_PARAVIEW_PYTHON_ROOT AND EXISTS "${CYLVOL_PARAVIEW_PYTHON_ROOT}${hierarchy}")
      set_property(TARGET "${target}" PROPERTY INTERFACE_vtk_module_hierarchy
        "${CYLVOL_PARAVIEW_PYTHON_ROOT}${hierarchy}")
    else ()
      math(EXPR missing "${missing} + 1")
    endif ()
  endforeach ()
  if (missing)
    message(FATAL_ERROR "${missing} of ParaView's wrapping hierarchy files (package "
      "python3-paraview) are neither installed nor under CYLVOL_PARAVIEW_PYTHON_ROOT "
      "('${CYLVOL_PARAVIEW_PYTHON_ROOT}'): unpack the package (apt-get download "
      "python3-paraview; dpkg -x python3-paraview_*.deb ROOT) and configure with "
      "-DCYLVOL_PARAVIEW_PYTHON_ROOT=ROOT")
  endif ()
endfunction ()
