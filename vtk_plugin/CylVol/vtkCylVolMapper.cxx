// vtkCylVolMapper: the VTK side of cylvol. It turns the VTK scene (grid, scalars, volume
// property, camera, z-buffer) into cylvol C ABI calls and shows the image cylvol returns
// through vtkRayCastImageDisplayHelper, the way vtkUnstructuredGridVolumeRayCastMapper does.
#include "vtkCylVolMapper.h"

#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellTypes.h"
#include "vtkColorTransferFunction.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkRayCastImageDisplayHelper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkTimerLog.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <cylvol.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkCylVolMapper);

namespace
{
// Entries of the colour and opacity tables. cylvol::render::VTK_MAPPER_TABLE_ENTRIES
// is the same number, so that `cylvol render --opacity-convention attenuation` reads a transfer
// function as this mapper does.
constexpr int kTableSize = 1024;

// Converts any VTK data array into a contiguous array cylvol accepts (f32 or f64). Float
// and double arrays are passed without copying; anything else is copied to double.
struct ValueView
{
  const void* Data = nullptr;
  CylvolValueType Type = CYLVOL_VALUE_F64;
  std::vector<double> Copy;

  void From(vtkDataArray* array)
  {
    const vtkIdType n = array->GetNumberOfTuples() * array->GetNumberOfComponents();
    if (array->GetDataType() == VTK_FLOAT && array->HasStandardMemoryLayout())
    {
      this->Data = array->GetVoidPointer(0);
      this->Type = CYLVOL_VALUE_F32;
      return;
    }
    if (array->GetDataType() == VTK_DOUBLE && array->HasStandardMemoryLayout())
    {
      this->Data = array->GetVoidPointer(0);
      this->Type = CYLVOL_VALUE_F64;
      return;
    }
    this->Copy.resize(static_cast<size_t>(n));
    const int nc = array->GetNumberOfComponents();
    for (vtkIdType t = 0; t < array->GetNumberOfTuples(); ++t)
    {
      for (int c = 0; c < nc; ++c)
      {
        this->Copy[static_cast<size_t>(t * nc + c)] = array->GetComponent(t, c);
      }
    }
    this->Data = this->Copy.data();
    this->Type = CYLVOL_VALUE_F64;
  }
};

// The cell connectivity as cylvol takes it (offsets + connectivity of one index width).
struct IndexView
{
  const void* Offsets = nullptr;
  const void* Connectivity = nullptr;
  CylvolIndexType Type = CYLVOL_INDEX_I64;
  size_t ConnectivityLength = 0;
};

bool SupportedCellType(unsigned char type)
{
  return type == VTK_HEXAHEDRON || type == VTK_VOXEL || type == VTK_WEDGE ||
    type == VTK_PYRAMID || type == VTK_TETRA;
}

// vtkUnstructuredGridVolumeMapper's blend modes, and vtkVolumeMapper's minimum intensity (the
// same value, 2), as cylvol's; false for any other.
bool BlendOf(int mode, CylvolBlend* out)
{
  switch (mode)
  {
    case vtkUnstructuredGridVolumeMapper::COMPOSITE_BLEND:
      *out = CYLVOL_BLEND_COMPOSITE;
      return true;
    case vtkUnstructuredGridVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      *out = CYLVOL_BLEND_MAXIMUM;
      return true;
    case 2:
      *out = CYLVOL_BLEND_MINIMUM;
      return true;
    default:
      return false;
  }
}

void ToRowMajor(vtkMatrix4x4* m, double out[16])
{
  vtkMatrix4x4::DeepCopy(out, m);
}

// The latest change of a grid's geometry: its points (object and values), cells and cell types.
vtkMTimeType GeometryMTime(vtkUnstructuredGrid* grid)
{
  vtkMTimeType t = 0;
  if (vtkPoints* points = grid->GetPoints())
  {
    t = std::max(points->GetMTime(), points->GetData()->GetMTime());
  }
  if (vtkCellArray* cells = grid->GetCells())
  {
    t = std::max(t, cells->GetMTime());
  }
  if (vtkUnsignedCharArray* types = grid->GetCellTypesArray())
  {
    t = std::max(t, types->GetMTime());
  }
  return t;
}

// A cylvol mesh of the grid's points, cells and cell types (copied by cylvol).
CylvolStatus NewMesh(vtkUnstructuredGrid* grid, CylvolMesh** mesh)
{
  ValueView points;
  points.From(grid->GetPoints()->GetData());
  vtkCellArray* cells = grid->GetCells();
  IndexView index;
  if (cells->IsStorage64Bit())
  {
    index.Offsets = cells->GetOffsetsArray64()->GetPointer(0);
    index.Connectivity = cells->GetConnectivityArray64()->GetPointer(0);
    index.Type = CYLVOL_INDEX_I64;
    index.ConnectivityLength = static_cast<size_t>(cells->GetConnectivityArray64()->GetNumberOfValues());
  }
  else
  {
    index.Offsets = cells->GetOffsetsArray32()->GetPointer(0);
    index.Connectivity = cells->GetConnectivityArray32()->GetPointer(0);
    index.Type = CYLVOL_INDEX_I32;
    index.ConnectivityLength = static_cast<size_t>(cells->GetConnectivityArray32()->GetNumberOfValues());
  }
  return cylvol_mesh_new(points.Data, points.Type, static_cast<size_t>(grid->GetNumberOfPoints()),
    index.Offsets, index.Connectivity, index.Type, index.ConnectivityLength,
    grid->GetCellTypesArray()->GetPointer(0), static_cast<size_t>(grid->GetNumberOfCells()), mesh);
}

std::string StatusText(CylvolStatus status)
{
  std::string text = cylvol_status_message(status);
  const char* detail = cylvol_last_error();
  if (detail && *detail)
  {
    text += ": ";
    text += detail;
  }
  return text;
}
} // namespace

//------------------------------------------------------------------------------
class vtkCylVolMapper::vtkInternals
{
public:
  CylvolVolume* Volume = nullptr;

  // The input without its ghost cells (VTK's vtkGhostType DUPLICATECELL and HIDDENCELL flags),
  // null when it has none, and how its points and cells map to the input's; for the input,
  // geometry and ghost array VisibleKey records.
  struct GhostKey
  {
    vtkUnstructuredGrid* Grid = nullptr; // compared only
    vtkMTimeType Geometry = 0;
    vtkUnsignedCharArray* Ghosts = nullptr; // compared only
    vtkMTimeType GhostsMTime = 0;
    vtkIdType Cells = -1;
    bool operator==(const GhostKey& o) const
    {
      return Grid == o.Grid && Geometry == o.Geometry && Ghosts == o.Ghosts &&
        GhostsMTime == o.GhostsMTime && Cells == o.Cells;
    }
  };
  GhostKey VisibleKey;
  bool VisibleKnown = false;
  vtkSmartPointer<vtkUnstructuredGrid> Visible;
  vtkSmartPointer<vtkIdList> VisiblePoints; // the input's id of each point of Visible
  vtkSmartPointer<vtkIdList> VisibleCells;  // the input's id of each cell of Visible

  // The input's scalars on Visible's points or cells (when Visible is used), refilled in place
  // when the input's array or its values change, so that new values are handed over without
  // a rebuild.
  vtkSmartPointer<vtkDataArray> VisibleScalars;
  vtkDataArray* VisibleScalarsOf = nullptr; // compared only
  vtkMTimeType VisibleScalarsMTime = 0;
  int VisibleScalarsCells = -1;

  // What the structure was built from.
  vtkUnstructuredGrid* BuiltInput = nullptr; // compared only, never dereferenced
  vtkMTimeType BuiltGeometryMTime = 0;
  vtkMTimeType BuiltSettingsMTime = 0;

  // What the current scalars came from.
  vtkDataArray* ScalarArray = nullptr; // compared only
  vtkMTimeType ScalarMTime = 0;
  int ScalarComponent = -2;
  int ScalarCells = -1;

  vtkTimeStamp SettingsTime; // structure settings' last change

  // How many cells of each VTK type the structure was last built over.
  std::vector<vtkIdType> BuiltCellCounts = std::vector<vtkIdType>(256, 0);

  // What the last render left out for cell scalars (1: shading, 2: gradient opacity), so that
  // the warning saying so is given once per change.
  int CellScalarsIgnored = 0;

  // The image (power-of-two memory like the VTK ray caster, rows bottom up).
  std::vector<unsigned char> Image;
  int ImageMemorySize[2] = { 0, 0 };
  std::vector<unsigned char> Tight; // width*height RGBA8 from cylvol
  std::vector<float> Depth;         // width*height window depth in [0,1]

  // Render time per (renderer, volume), for AutoAdjustSampleDistances.
  struct TimeEntry
  {
    vtkRenderer* Ren;
    vtkVolume* Vol;
    double Seconds;
  };
  std::vector<TimeEntry> Times;

  double RetrieveTime(vtkRenderer* ren, vtkVolume* vol) const
  {
    for (const auto& e : this->Times)
    {
      if (e.Ren == ren && e.Vol == vol)
      {
        return e.Seconds;
      }
    }
    return 0.0;
  }
  void StoreTime(vtkRenderer* ren, vtkVolume* vol, double seconds)
  {
    for (auto& e : this->Times)
    {
      if (e.Ren == ren && e.Vol == vol)
      {
        e.Seconds = seconds;
        return;
      }
    }
    this->Times.push_back({ ren, vol, seconds });
  }

  // `grid`, or a copy of its geometry without the cells its ghost array flags as another
  // piece's or hidden (made by vtkUnstructuredGrid::RemoveGhostCells, which also drops the
  // points only those cells use): the input is left as it is. The answer (the copy, or none
  // needed) is kept while the input's points, cells and ghost array are unchanged, so that
  // neither an unchanged input nor new scalars (values, another array) scan, copy or rebuild
  // anything; Scalars gives the input's scalars on the copy.
  vtkUnstructuredGrid* WithoutGhostCells(vtkUnstructuredGrid* grid)
  {
    GhostKey key;
    key.Grid = grid;
    key.Geometry = GeometryMTime(grid);
    key.Ghosts = grid->GetCellGhostArray();
    key.GhostsMTime = key.Ghosts ? key.Ghosts->GetMTime() : 0;
    key.Cells = grid->GetNumberOfCells();
    if (this->VisibleKnown && this->VisibleKey == key)
    {
      return this->Visible ? this->Visible.Get() : grid;
    }
    this->VisibleKnown = true;
    this->VisibleKey = key;
    this->Visible = nullptr;
    this->VisiblePoints = nullptr;
    this->VisibleCells = nullptr;
    this->VisibleScalars = nullptr;
    this->VisibleScalarsOf = nullptr;
    vtkUnsignedCharArray* ghosts = key.Ghosts;
    const unsigned char flags = vtkDataSetAttributes::DUPLICATECELL | vtkDataSetAttributes::HIDDENCELL;
    bool any = false;
    if (ghosts && ghosts->GetNumberOfTuples() == grid->GetNumberOfCells() && grid->GetPoints() &&
      grid->GetCells() && grid->GetCellTypesArray())
    {
      const unsigned char* g = ghosts->GetPointer(0);
      const vtkIdType n = ghosts->GetNumberOfTuples();
      for (vtkIdType i = 0; i < n && !any; ++i)
      {
        any = (g[i] & flags) != 0;
      }
    }
    if (!any)
    {
      return grid;
    }
    // The geometry alone (the input's points, cells and ghost flags) with each point's and
    // cell's id, so that the copy tells where its points and cells come from.
    auto visible = vtkSmartPointer<vtkUnstructuredGrid>::New();
    visible->SetPoints(grid->GetPoints());
    visible->SetCells(grid->GetCellTypesArray(), grid->GetCells());
    visible->GetCellData()->AddArray(ghosts);
    vtkNew<vtkIdTypeArray> pointIds;
    pointIds->SetName("vtkCylVolPointIds");
    pointIds->SetNumberOfTuples(grid->GetNumberOfPoints());
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
    {
      pointIds->SetValue(i, i);
    }
    visible->GetPointData()->AddArray(pointIds);
    vtkNew<vtkIdTypeArray> cellIds;
    cellIds->SetName("vtkCylVolCellIds");
    cellIds->SetNumberOfTuples(grid->GetNumberOfCells());
    for (vtkIdType i = 0; i < grid->GetNumberOfCells(); ++i)
    {
      cellIds->SetValue(i, i);
    }
    visible->GetCellData()->AddArray(cellIds);
    visible->RemoveGhostCells();
    this->VisiblePoints = IdsOf(visible->GetPointData()->GetAbstractArray("vtkCylVolPointIds"));
    this->VisibleCells = IdsOf(visible->GetCellData()->GetAbstractArray("vtkCylVolCellIds"));
    visible->GetPointData()->Initialize();
    visible->GetCellData()->Initialize();
    this->Visible = visible;
    return this->Visible;
  }

  // `scalars` of the input (cell data when `cells`) as the grid WithoutGhostCells returned
  // has them: `scalars` itself when it is the input, else their values on the copy's points
  // or cells, gathered again only when the array or its values change.
  vtkDataArray* Scalars(vtkDataArray* scalars, int cells)
  {
    if (!this->Visible)
    {
      return scalars;
    }
    if (this->VisibleScalars && this->VisibleScalarsOf == scalars &&
      this->VisibleScalarsMTime == scalars->GetMTime() && this->VisibleScalarsCells == cells)
    {
      return this->VisibleScalars;
    }
    vtkIdList* ids = cells ? this->VisibleCells.Get() : this->VisiblePoints.Get();
    if (!this->VisibleScalars || this->VisibleScalars->GetDataType() != scalars->GetDataType())
    {
      this->VisibleScalars = vtk::TakeSmartPointer(scalars->NewInstance());
    }
    this->VisibleScalars->SetName(scalars->GetName());
    this->VisibleScalars->SetNumberOfComponents(scalars->GetNumberOfComponents());
    this->VisibleScalars->SetNumberOfTuples(ids->GetNumberOfIds());
    scalars->GetTuples(ids, this->VisibleScalars);
    this->VisibleScalars->Modified();
    this->VisibleScalarsOf = scalars;
    this->VisibleScalarsMTime = scalars->GetMTime();
    this->VisibleScalarsCells = cells;
    return this->VisibleScalars;
  }

  // The ids RemoveGhostCells kept of an id array WithoutGhostCells attached.
  static vtkSmartPointer<vtkIdList> IdsOf(vtkAbstractArray* array)
  {
    auto ids = vtkSmartPointer<vtkIdList>::New();
    vtkIdTypeArray* kept = vtkIdTypeArray::SafeDownCast(array);
    const vtkIdType n = kept ? kept->GetNumberOfTuples() : 0;
    ids->SetNumberOfIds(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      ids->SetId(i, kept->GetValue(i));
    }
    return ids;
  }

  void FreeVolume()
  {
    cylvol_volume_free(this->Volume);
    this->Volume = nullptr;
    this->BuiltInput = nullptr;
    this->ScalarArray = nullptr;
  }
};

//------------------------------------------------------------------------------
vtkCylVolMapper::vtkCylVolMapper()
{
  this->Structure = STRUCTURE_AUTO;
  this->AxisAuto = 1;
  this->AxisOrigin[0] = this->AxisOrigin[1] = this->AxisOrigin[2] = 0.0;
  this->AxisDirection[0] = this->AxisDirection[1] = 0.0;
  this->AxisDirection[2] = 1.0;
  this->BuildPreset = 0;
  this->PeriodicCopies = 0;
  this->CopyRange[0] = this->CopyRange[1] = 0;
  this->BuiltPeriodicCopies = 0;
  this->BuiltCopyRange[0] = this->BuiltCopyRange[1] = 0;
  this->BuiltPeriodicSpan = 0.0;
  this->BuiltPeriodicMismatch = 0.0;
  this->EarlyTermination = 0.99;
  this->SampleDistance = 0.0;
  this->RelativeSampleDistance = 1.0;
  {
    // cylvol's own default (6 cells), so that the two never drift apart.
    CylvolRenderParams defaults;
    cylvol_render_params_default(&defaults);
    this->MarchReach = defaults.march_reach;
    this->MaximumError = defaults.max_error;
  }
  this->ImageSampleDistance = 1.0f;
  this->MinimumImageSampleDistance = 1.0f;
  this->MaximumImageSampleDistance = 10.0f;
  this->AutoAdjustSampleDistances = 0;
  this->ScalarComponent = -1;
  this->OpacityConvention = OPACITY_ATTENUATION;
  this->IntermixIntersectingGeometry = 1;

  this->LastRenderSeconds = 0.0;
  this->LastRaySeconds = 0.0;
  this->LastRays = this->LastSamples = this->LastSamplesLocated = this->LastHexTests = 0;
  this->LastInternalVisits = this->LastLeafVisits = 0;
  this->LastGradientEvaluations = this->LastEarlyTerminations = 0;
  this->LastSamplesSkipped = this->LastPlaneCertified = this->LastWalkSteps = 0;
  this->LastTransparentJumps = 0;
  this->LastExtremeSkips = 0;
  this->LastExtremeJumps = 0;
  this->LastFarLocates = 0;
  this->LastRefinedSamples = this->LastSlopes = this->LastIntegratedStretches = 0;
  this->LastImageSize[0] = this->LastImageSize[1] = 0;
  this->BuildCount = 0;
  this->ScalarUpdateCount = 0;
  this->LastBuildSeconds = 0.0;
  this->LastBuildBytes = 0;
  this->BuiltStructure = -1;
  this->BuiltAxisOrigin[0] = this->BuiltAxisOrigin[1] = this->BuiltAxisOrigin[2] = 0.0;
  this->BuiltAxisDirection[0] = this->BuiltAxisDirection[1] = this->BuiltAxisDirection[2] = 0.0;
  this->LastSampleDistance = 0.0;

  this->ImageDisplayHelper = vtkRayCastImageDisplayHelper::New();
  if (this->ImageDisplayHelper)
  {
    this->ImageDisplayHelper->PreMultipliedColorsOn();
  }
  this->Timer = vtkTimerLog::New();
  this->Internals = new vtkInternals;
  this->Internals->SettingsTime.Modified();
}

//------------------------------------------------------------------------------
vtkCylVolMapper::~vtkCylVolMapper()
{
  this->Internals->FreeVolume();
  delete this->Internals;
  if (this->ImageDisplayHelper)
  {
    this->ImageDisplayHelper->Delete();
  }
  this->Timer->Delete();
}

//------------------------------------------------------------------------------
const char* vtkCylVolMapper::GetCylVolVersion()
{
  return cylvol_version();
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::SetStructure(int structure)
{
  structure = std::max<int>(STRUCTURE_AUTO, std::min<int>(STRUCTURE_CYLINDRICAL_BVH, structure));
  if (structure != this->Structure)
  {
    this->Structure = structure;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetAxisAuto(vtkTypeBool value)
{
  value = value ? 1 : 0;
  if (value != this->AxisAuto)
  {
    this->AxisAuto = value;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetAxisOrigin(double x, double y, double z)
{
  if (x != this->AxisOrigin[0] || y != this->AxisOrigin[1] || z != this->AxisOrigin[2])
  {
    this->AxisOrigin[0] = x;
    this->AxisOrigin[1] = y;
    this->AxisOrigin[2] = z;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetAxisDirection(double x, double y, double z)
{
  if (x != this->AxisDirection[0] || y != this->AxisDirection[1] || z != this->AxisDirection[2])
  {
    this->AxisDirection[0] = x;
    this->AxisDirection[1] = y;
    this->AxisDirection[2] = z;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetBuildPreset(int preset)
{
  if (preset != this->BuildPreset)
  {
    this->BuildPreset = preset;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetPeriodicCopies(int copies)
{
  if (copies != this->PeriodicCopies)
  {
    this->PeriodicCopies = copies;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetCopyRange(int first, int end)
{
  if (first != this->CopyRange[0] || end != this->CopyRange[1])
  {
    this->CopyRange[0] = first;
    this->CopyRange[1] = end;
    this->Internals->SettingsTime.Modified();
    this->Modified();
  }
}

void vtkCylVolMapper::SetScalarComponent(int component)
{
  if (component != this->ScalarComponent)
  {
    this->ScalarComponent = component;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkIdType vtkCylVolMapper::GetBuiltCellCount(int cellType)
{
  return cellType >= 0 && cellType < 256 ? this->Internals->BuiltCellCounts[cellType] : 0;
}

//------------------------------------------------------------------------------
int vtkCylVolMapper::FillInputPortInformation(int port, vtkInformation* info)
{
  if (!this->Superclass::FillInputPortInformation(port, info))
  {
    return 0;
  }
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  if (this->ImageDisplayHelper)
  {
    this->ImageDisplayHelper->ReleaseGraphicsResources(win);
  }
}

//------------------------------------------------------------------------------
// One frame's state, filled in by the steps of Render in turn.
struct vtkCylVolMapper::Frame
{
  CylvolBlend Blend = CYLVOL_BLEND_COMPOSITE;

  // The input as given, and the grid drawn (the input without its ghost cells).
  vtkUnstructuredGrid* Input = nullptr;
  vtkUnstructuredGrid* Grid = nullptr;

  // The scalars drawn (on Grid's points or cells), whether they are cell data, and the
  // component drawn.
  vtkVolumeProperty* Property = nullptr;
  vtkDataArray* Scalars = nullptr;
  int CellFlag = 0;
  int Component = 0;

  // The transfer tables and the CylvolTransfer that points into them.
  std::vector<float> Rgb;
  std::vector<float> Opacity;
  std::vector<float> GradientOpacity;
  CylvolTransfer Transfer;

  // The image: its size, the viewport it covers, and the depth of what is already drawn
  // (null when nothing stops the rays).
  float OldImageSampleDistance = 1.0f;
  int Width = 0;
  int Height = 0;
  int ViewportWidth = 0;
  int ViewportHeight = 0;
  int ViewportX = 0;
  int ViewportY = 0;
  size_t PixelCount = 0;
  const float* DepthIn = nullptr;

  // The camera: the view matrix in `Camera`, the whole image's projection in ProjectionRows.
  double Aspect = 1.0;
  CylvolCamera Camera;
  double ProjectionRows[16];

  CylvolRenderParams Params;
};

//------------------------------------------------------------------------------
void vtkCylVolMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  this->Timer->StartTimer();
  this->ResetRenderStatistics();
  Frame frame;
  // Settings that draw nothing are refused before any build.
  if (!BlendOf(this->BlendMode, &frame.Blend))
  {
    vtkErrorMacro(<< "Unsupported blend mode " << this->BlendMode
                  << "; vtkCylVolMapper composites (0), or projects the maximum (1) or the "
                     "minimum (2) intensity: nothing drawn.");
    return;
  }
  frame.Property = vol->GetProperty();
  if (!this->PrepareVolume(frame) || !this->MakeTransferTables(frame))
  {
    return;
  }
  this->SizeImage(frame, ren, vol);
  this->ReadDepth(frame, ren);
  this->SetCamera(frame, ren, vol);
  this->SetRenderParameters(frame, vol);
  if (!this->RenderBands(frame, ren))
  {
    return;
  }
  this->Display(frame, ren, vol);
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::PrepareVolume(Frame& frame)
{
  return this->SelectInput(frame) && this->SelectScalars(frame) && this->CheckCellTypes(frame) &&
    this->UpdateVolume(frame);
}

//------------------------------------------------------------------------------
double* vtkCylVolMapper::GetBounds()
{
  double* bounds = this->Superclass::GetBounds();
  if (this->PeriodicCopies == 0)
  {
    return bounds;
  }
  // The bounds are asked for before any render (a camera reset): the volume property's
  // defaults choose the component here, as they would have the volume's.
  vtkNew<vtkVolumeProperty> defaults;
  Frame frame;
  frame.Property = defaults;
  CylvolBuildStats bs;
  if (this->PrepareVolume(frame) &&
    cylvol_volume_build_stats(this->Internals->Volume, &bs) == CYLVOL_STATUS_OK)
  {
    std::copy(bs.bounds, bs.bounds + 6, this->Bounds);
  }
  return this->Bounds;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::ResetRenderStatistics()
{
  this->LastRays = this->LastSamples = this->LastSamplesLocated = this->LastHexTests = 0;
  this->LastInternalVisits = this->LastLeafVisits = 0;
  this->LastGradientEvaluations = this->LastEarlyTerminations = 0;
  this->LastSamplesSkipped = this->LastPlaneCertified = this->LastWalkSteps = 0;
  this->LastTransparentJumps = 0;
  this->LastExtremeSkips = 0;
  this->LastExtremeJumps = 0;
  this->LastFarLocates = 0;
  this->LastRefinedSamples = this->LastSlopes = this->LastIntegratedStretches = 0;
  this->LastRaySeconds = 0.0;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::SelectInput(Frame& frame)
{
  if (this->GetNumberOfInputConnections(0) == 0)
  {
    vtkErrorMacro(<< "No input: nothing drawn.");
    return false;
  }
  if (this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->UpdateInformation();
    this->GetInputAlgorithm()->Update();
  }
  vtkUnstructuredGridBase* base = this->GetInput();
  vtkUnstructuredGrid* input = vtkUnstructuredGrid::SafeDownCast(base);
  if (!input)
  {
    // What the pipeline gave: VTK's executive reports another type too, but leaves it to the
    // mapper to say what it draws.
    vtkDataObject* given = base ? base : this->GetInputDataObject(0, 0);
    vtkAlgorithm* producer = this->GetInputAlgorithm();
    if (given)
    {
      vtkErrorMacro(<< "The input is a " << given->GetClassName()
                    << ", but vtkCylVolMapper needs a vtkUnstructuredGrid: nothing drawn.");
    }
    else
    {
      vtkErrorMacro(<< "The input connection (" << (producer ? producer->GetClassName() : "none")
                    << ") produced no data object; vtkCylVolMapper needs a vtkUnstructuredGrid: "
                       "nothing drawn.");
    }
    return false;
  }
  vtkUnstructuredGrid* grid = this->Internals->WithoutGhostCells(input);
  if (grid->GetNumberOfCells() == 0 || grid->GetNumberOfPoints() == 0 || !grid->GetPoints() ||
    !grid->GetCells() || !grid->GetCellTypesArray())
  {
    vtkErrorMacro(<< "The input grid is empty (" << grid->GetNumberOfPoints() << " points, "
                  << grid->GetNumberOfCells() << " cells): nothing drawn.");
    return false;
  }
  frame.Input = input;
  frame.Grid = grid;
  return true;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::SelectScalars(Frame& frame)
{
  vtkUnstructuredGrid* input = frame.Input;
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(input, this->ScalarMode,
    this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag);
  if (!scalars)
  {
    vtkErrorMacro(<< "No scalars to render (scalar mode " << this->GetScalarModeAsString()
                  << (this->ArrayName ? ", array " : "") << (this->ArrayName ? this->ArrayName : "")
                  << "): nothing drawn.");
    return false;
  }
  // Several components. VTK's unstructured mappers draw each component through its own
  // transfer functions and mix them (the volume property's IndependentComponents, on by
  // default), or, with IndependentComponents off, read 2 or 4 components as colour and opacity
  // themselves. cylvol draws one scalar through one pair of tables: ScalarComponent chooses
  // it, drawn with the property's first transfer functions (as vtkSmartVolumeMapper's
  // component mode draws one); dependent components are refused. One component is drawn
  // whatever IndependentComponents says: nothing depends on anything.
  int component = 0;
  const int components = scalars->GetNumberOfComponents();
  if (components > 1)
  {
    const char* arrayName = scalars->GetName() ? scalars->GetName() : "";
    if (!frame.Property->GetIndependentComponents())
    {
      vtkErrorMacro(<< "The scalar array '" << arrayName << "' has " << components
                    << " components and the volume property's IndependentComponents is off, "
                       "so they are to be read as colour and opacity (VTK's dependent "
                       "components); vtkCylVolMapper draws one component through the transfer "
                       "functions: turn IndependentComponents on and choose the component with "
                       "SetScalarComponent: nothing drawn.");
      return false;
    }
    if (this->ScalarComponent == SCALAR_MAGNITUDE)
    {
      component = -1; // cylvol's magnitude
    }
    else if (this->ScalarComponent < 0 || this->ScalarComponent >= components)
    {
      vtkErrorMacro(<< "The scalar array '" << arrayName << "' has " << components
                    << " components and no valid component is chosen (ScalarComponent = "
                    << this->ScalarComponent
                    << "); VTK's unstructured mappers would mix all of them, each through its "
                       "own transfer functions (IndependentComponents), vtkCylVolMapper draws one: "
                       "choose it with SetScalarComponent(0.."
                    << components - 1 << ") or draw the magnitude (SCALAR_MAGNITUDE): nothing "
                       "drawn.");
      return false;
    }
    else
    {
      component = this->ScalarComponent;
    }
  }
  const vtkIdType expectedTuples = cellFlag ? input->GetNumberOfCells() : input->GetNumberOfPoints();
  if (scalars->GetNumberOfTuples() != expectedTuples)
  {
    vtkErrorMacro(<< "The scalar array has " << scalars->GetNumberOfTuples() << " tuples but the grid has "
                  << expectedTuples << (cellFlag ? " cells" : " points") << ": nothing drawn.");
    return false;
  }
  // Without ghost cells, the values on the points and cells drawn.
  frame.Scalars = this->Internals->Scalars(scalars, cellFlag);
  frame.CellFlag = cellFlag;
  frame.Component = component;
  return true;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::CheckCellTypes(Frame& frame)
{
  vtkUnsignedCharArray* types = frame.Grid->GetCellTypesArray();
  const unsigned char* t = types->GetPointer(0);
  const vtkIdType n = types->GetNumberOfTuples();
  for (vtkIdType i = 0; i < n; ++i)
  {
    if (!SupportedCellType(t[i]))
    {
      const char* name = vtkCellTypes::GetClassNameFromTypeId(t[i]);
      vtkErrorMacro(<< "Unsupported cell type " << static_cast<int>(t[i]) << " ("
                    << (name ? name : "unknown") << ") at cell " << i
                    << "; vtkCylVolMapper takes hexahedra, voxels, wedges, pyramids and "
                       "tetrahedra: nothing drawn.");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::UpdateVolume(Frame& frame)
{
  vtkInternals& in = *this->Internals;
  vtkDataArray* scalars = frame.Scalars;
  const bool rebuild = !in.Volume || in.BuiltInput != frame.Grid ||
    in.BuiltGeometryMTime != GeometryMTime(frame.Grid) ||
    in.BuiltSettingsMTime != in.SettingsTime.GetMTime();
  if (rebuild)
  {
    return this->BuildVolume(frame);
  }
  if (in.ScalarArray != scalars || in.ScalarMTime != scalars->GetMTime() ||
    in.ScalarComponent != frame.Component || in.ScalarCells != frame.CellFlag)
  {
    return this->ReplaceScalars(frame);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::BuildVolume(Frame& frame)
{
  vtkInternals& in = *this->Internals;
  vtkUnstructuredGrid* grid = frame.Grid;
  vtkDataArray* scalars = frame.Scalars;
  in.FreeVolume();
  if (grid->GetPoints()->GetData()->GetNumberOfComponents() != 3)
  {
    vtkErrorMacro(<< "The points do not have 3 components: nothing drawn.");
    return false;
  }
  CylvolMesh* mesh = nullptr;
  CylvolStatus status = NewMesh(grid, &mesh);
  if (status != CYLVOL_STATUS_OK)
  {
    vtkErrorMacro(<< "cylvol rejected the grid: " << StatusText(status) << ": nothing drawn.");
    return false;
  }
  ValueView values;
  values.From(scalars);
  status = cylvol_mesh_set_scalars(mesh, scalars->GetName(),
    frame.CellFlag ? CYLVOL_CELL_DATA : CYLVOL_POINT_DATA, values.Data, values.Type,
    static_cast<size_t>(scalars->GetNumberOfTuples()),
    static_cast<size_t>(scalars->GetNumberOfComponents()), frame.Component);
  if (status != CYLVOL_STATUS_OK)
  {
    vtkErrorMacro(<< "cylvol rejected the scalars: " << StatusText(status) << ": nothing drawn.");
    cylvol_mesh_free(mesh);
    return false;
  }
  CylvolBuildParams params;
  cylvol_build_params_default(&params);
  params.structure = static_cast<CylvolStructure>(this->Structure);
  params.axis_auto = this->AxisAuto ? 1 : 0;
  for (int k = 0; k < 3; ++k)
  {
    params.axis_origin[k] = this->AxisOrigin[k];
    params.axis_direction[k] = this->AxisDirection[k];
  }
  params.preset = this->BuildPreset;
  params.periodic = this->PeriodicCopies;
  params.copies_first = this->CopyRange[0];
  params.copies_end = this->CopyRange[1];
  CylvolVolume* volume = nullptr;
  status = cylvol_volume_new(mesh, &params, &volume);
  cylvol_mesh_free(mesh);
  if (status != CYLVOL_STATUS_OK)
  {
    vtkErrorMacro(<< "cylvol could not build the structure: " << StatusText(status)
                  << ": nothing drawn.");
    return false;
  }
  in.Volume = volume;
  in.BuiltInput = grid;
  in.BuiltGeometryMTime = GeometryMTime(grid);
  in.BuiltSettingsMTime = in.SettingsTime.GetMTime();
  in.ScalarArray = scalars;
  in.ScalarMTime = scalars->GetMTime();
  in.ScalarComponent = frame.Component;
  in.ScalarCells = frame.CellFlag;
  this->BuildCount++;
  this->RecordBuildStatistics();
  std::fill(in.BuiltCellCounts.begin(), in.BuiltCellCounts.end(), 0);
  const unsigned char* types = grid->GetCellTypesArray()->GetPointer(0);
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
  {
    in.BuiltCellCounts[types[c]]++;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::RecordBuildStatistics()
{
  CylvolBuildStats bs;
  if (cylvol_volume_build_stats(this->Internals->Volume, &bs) != CYLVOL_STATUS_OK)
  {
    return;
  }
  this->LastBuildSeconds = bs.build_seconds;
  this->LastBuildBytes = bs.bytes;
  this->BuiltStructure = static_cast<int>(bs.structure);
  for (int k = 0; k < 3; ++k)
  {
    this->BuiltAxisOrigin[k] = bs.axis_origin[k];
    this->BuiltAxisDirection[k] = bs.axis_direction[k];
  }
  this->BuiltPeriodicCopies = bs.periodic_copies;
  this->BuiltCopyRange[0] = bs.copies_first;
  this->BuiltCopyRange[1] = bs.copies_end;
  this->BuiltPeriodicSpan = bs.periodic_span_degrees;
  this->BuiltPeriodicMismatch = bs.periodic_worst_mismatch;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::ReplaceScalars(Frame& frame)
{
  vtkInternals& in = *this->Internals;
  vtkDataArray* scalars = frame.Scalars;
  ValueView values;
  values.From(scalars);
  const CylvolStatus status = cylvol_volume_set_scalars(in.Volume, scalars->GetName(),
    frame.CellFlag ? CYLVOL_CELL_DATA : CYLVOL_POINT_DATA, values.Data, values.Type,
    static_cast<size_t>(scalars->GetNumberOfTuples()),
    static_cast<size_t>(scalars->GetNumberOfComponents()), frame.Component);
  if (status != CYLVOL_STATUS_OK)
  {
    vtkErrorMacro(<< "cylvol rejected the new scalars: " << StatusText(status)
                  << ": nothing drawn.");
    in.ScalarArray = nullptr;
    return false;
  }
  in.ScalarArray = scalars;
  in.ScalarMTime = scalars->GetMTime();
  in.ScalarComponent = frame.Component;
  in.ScalarCells = frame.CellFlag;
  this->ScalarUpdateCount++;
  return true;
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::MakeTransferTables(Frame& frame)
{
  vtkVolumeProperty* property = frame.Property;
  double range[2];
  frame.Scalars->GetRange(range, frame.Component);
  if (this->BuiltPeriodicCopies > 0)
  {
    // A vector's component turns with each copy: the tables span its range over them all.
    double drawn[2];
    if (cylvol_volume_scalar_range(this->Internals->Volume, drawn) == CYLVOL_STATUS_OK)
    {
      range[0] = drawn[0];
      range[1] = drawn[1];
    }
  }
  if (!(range[1] > range[0]))
  {
    const double pad = std::max(1e-6, std::abs(range[0]) * 1e-6);
    range[0] -= pad;
    range[1] += pad;
  }
  std::vector<float>& rgb = frame.Rgb;
  std::vector<float>& opacity = frame.Opacity;
  rgb.resize(3 * kTableSize);
  opacity.resize(kTableSize);
  {
    std::vector<double> tmp(3 * kTableSize);
    if (property->GetColorChannels(0) == 1)
    {
      property->GetGrayTransferFunction(0)->GetTable(range[0], range[1], kTableSize, tmp.data());
      for (int i = 0; i < kTableSize; ++i)
      {
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] =
          static_cast<float>(vtkMath::ClampValue(tmp[i], 0.0, 1.0));
      }
    }
    else
    {
      property->GetRGBTransferFunction(0)->GetTable(range[0], range[1], kTableSize, tmp.data());
      for (int i = 0; i < 3 * kTableSize; ++i)
      {
        rgb[i] = static_cast<float>(vtkMath::ClampValue(tmp[i], 0.0, 1.0));
      }
    }
    property->GetScalarOpacity(0)->GetTable(range[0], range[1], kTableSize, tmp.data());
    for (int i = 0; i < kTableSize; ++i)
    {
      double a = std::max(0.0, tmp[i]);
      if (this->OpacityConvention == OPACITY_ATTENUATION)
      {
        // VTK's unstructured ray caster reads opacity / unit distance as an attenuation
        // coefficient; cylvol composites (1 - a')^(step / unit): a' = 1 - exp(-a).
        a = -std::expm1(-a);
      }
      opacity[i] = static_cast<float>(vtkMath::ClampValue(a, 0.0, 1.0));
    }
  }
  CylvolTransfer& transfer = frame.Transfer;
  transfer.rgb = rgb.data();
  transfer.n_color = kTableSize;
  transfer.opacity = opacity.data();
  transfer.n_opacity = kTableSize;
  transfer.range[0] = range[0];
  transfer.range[1] = range[1];
  transfer.unit_distance = property->GetScalarOpacityUnitDistance(0);
  if (!(transfer.unit_distance > 0.0))
  {
    vtkErrorMacro(<< "ScalarOpacityUnitDistance must be > 0: nothing drawn.");
    return false;
  }
  transfer.gradient_opacity = nullptr;
  transfer.n_gradient_opacity = 0;
  transfer.gradient_range[0] = 0.0;
  transfer.gradient_range[1] = 1.0;
  if (!property->GetDisableGradientOpacity(0) && property->HasGradientOpacity(0))
  {
    vtkPiecewiseFunction* go = property->GetStoredGradientOpacity(0);
    bool constantOne = true;
    const int n = go ? go->GetSize() : 0;
    for (int i = 0; i < n; ++i)
    {
      double node[4];
      go->GetNodeValue(i, node);
      constantOne = constantOne && node[1] == 1.0;
    }
    if (go && n > 0 && !constantOne)
    {
      double gr[2];
      go->GetRange(gr);
      if (!(gr[1] > gr[0]))
      {
        gr[1] = gr[0] + 1.0;
      }
      std::vector<double> tmp(kTableSize);
      go->GetTable(gr[0], gr[1], kTableSize, tmp.data());
      std::vector<float>& gradientTable = frame.GradientOpacity;
      gradientTable.resize(kTableSize);
      for (int i = 0; i < kTableSize; ++i)
      {
        gradientTable[i] = static_cast<float>(vtkMath::ClampValue(tmp[i], 0.0, 1.0));
      }
      transfer.gradient_opacity = gradientTable.data();
      transfer.n_gradient_opacity = kTableSize;
      transfer.gradient_range[0] = gr[0];
      transfer.gradient_range[1] = gr[1];
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::SizeImage(Frame& frame, vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& in = *this->Internals;
  frame.OldImageSampleDistance = this->ImageSampleDistance;
  if (this->AutoAdjustSampleDistances)
  {
    const double oldTime = in.RetrieveTime(ren, vol);
    const double newTime = vol->GetAllocatedRenderTime();
    if (oldTime > 0.0 && newTime > 0.0)
    {
      float isd = static_cast<float>(this->ImageSampleDistance * std::sqrt(oldTime / newTime));
      isd = std::min(isd, this->MaximumImageSampleDistance);
      isd = std::max(isd, this->MinimumImageSampleDistance);
      this->ImageSampleDistance = isd;
    }
  }
  ren->GetTiledSizeAndOrigin(
    &frame.ViewportWidth, &frame.ViewportHeight, &frame.ViewportX, &frame.ViewportY);
  const int width = std::max(1, static_cast<int>(frame.ViewportWidth / this->ImageSampleDistance));
  const int height = std::max(1, static_cast<int>(frame.ViewportHeight / this->ImageSampleDistance));
  frame.Width = width;
  frame.Height = height;
  this->LastImageSize[0] = width;
  this->LastImageSize[1] = height;
  int memorySize[2] = { 32, 32 };
  while (memorySize[0] < width)
  {
    memorySize[0] *= 2;
  }
  while (memorySize[1] < height)
  {
    memorySize[1] *= 2;
  }
  if (in.ImageMemorySize[0] != memorySize[0] || in.ImageMemorySize[1] != memorySize[1])
  {
    in.Image.assign(static_cast<size_t>(memorySize[0]) * memorySize[1] * 4, 0);
    in.ImageMemorySize[0] = memorySize[0];
    in.ImageMemorySize[1] = memorySize[1];
  }
  frame.PixelCount = static_cast<size_t>(width) * static_cast<size_t>(height);
  in.Tight.assign(frame.PixelCount * 4, 0);
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::ReadDepth(Frame& frame, vtkRenderer* ren)
{
  vtkInternals& in = *this->Internals;
  frame.DepthIn = nullptr;
  if (!this->IntermixIntersectingGeometry || ren->GetNumberOfPropsRendered() == 0)
  {
    return;
  }
  const int vw = frame.ViewportWidth, vh = frame.ViewportHeight;
  float* z = ren->GetRenderWindow()->GetZbufferData(
    frame.ViewportX, frame.ViewportY, frame.ViewportX + vw - 1, frame.ViewportY + vh - 1);
  if (!z)
  {
    return;
  }
  const int width = frame.Width, height = frame.Height;
  in.Depth.resize(frame.PixelCount);
  for (int j = 0; j < height; ++j)
  {
    int zy = static_cast<int>((j + 0.5) * vh / height);
    zy = std::min(std::max(zy, 0), vh - 1);
    for (int i = 0; i < width; ++i)
    {
      int zx = static_cast<int>((i + 0.5) * vw / width);
      zx = std::min(std::max(zx, 0), vw - 1);
      in.Depth[static_cast<size_t>(j) * width + i] = z[static_cast<size_t>(zy) * vw + zx];
    }
  }
  delete[] z;
  frame.DepthIn = in.Depth.data();
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::SetCamera(Frame& frame, vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& in = *this->Internals;
  vtkCamera* cam = ren->GetActiveCamera();
  frame.Aspect = ren->GetTiledAspectRatio();
  vtkNew<vtkMatrix4x4> view;
  vtkMatrix4x4::Multiply4x4(cam->GetModelViewTransformMatrix(), vol->GetMatrix(), view);
  vtkNew<vtkMatrix4x4> projection;
  projection->DeepCopy(cam->GetProjectionTransformMatrix(frame.Aspect, -1, 1));

  cylvol_camera_default(&frame.Camera);
  frame.Camera.mode = CYLVOL_CAMERA_MATRICES;
  ToRowMajor(view, frame.Camera.view);
  ToRowMajor(projection, frame.ProjectionRows);

  // The far clipping plane. The rays start on the near plane, but cylvol reads a window depth
  // of 1 (the far plane, and the z-buffer where nothing is drawn) as no depth at all, and
  // would march past it. vtkUnstructuredGridVolumeRayCastMapper bounds every ray by the
  // window depths [0, 1], so where the far plane cuts the volume's bounds each ray stops just
  // before it: its depth is at most the largest window depth below 1. A volume in front of
  // the far plane is drawn with the z-buffer alone.
  double clippingRange[2];
  cam->GetClippingRange(clippingRange);
  double bounds[6];
  vol->GetBounds(bounds);
  vtkMatrix4x4* modelView = cam->GetModelViewTransformMatrix();
  bool farCuts = false;
  for (int k = 0; k < 8 && !farCuts; ++k)
  {
    double p[4] = { bounds[k & 1], bounds[2 + ((k >> 1) & 1)], bounds[4 + ((k >> 2) & 1)], 1.0 };
    modelView->MultiplyPoint(p, p);
    // Eye space looks down -z; the clipping range holds distances along the view direction.
    farCuts = -p[2] / p[3] > clippingRange[1];
  }
  if (!farCuts)
  {
    return;
  }
  const float farDepth = std::nextafter(1.0f, 0.0f);
  if (frame.DepthIn)
  {
    for (float& z : in.Depth)
    {
      z = std::min(z, farDepth);
    }
  }
  else
  {
    in.Depth.assign(frame.PixelCount, farDepth);
    frame.DepthIn = in.Depth.data();
  }
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::SetRenderParameters(Frame& frame, vtkVolume* vol)
{
  vtkInternals& in = *this->Internals;
  vtkVolumeProperty* property = frame.Property;
  CylvolRenderParams& params = frame.Params;
  cylvol_render_params_default(&params);
  params.width = static_cast<uint32_t>(frame.Width);
  params.step = this->SampleDistance;
  params.path = CYLVOL_PATH_FAST;
  params.interpolation = property->GetInterpolationType() == VTK_NEAREST_INTERPOLATION
    ? CYLVOL_INTERPOLATION_NEAREST
    : CYLVOL_INTERPOLATION_LINEAR;
  params.shading = property->GetShade(0) ? 1 : 0;
  params.ambient = property->GetAmbient(0);
  params.diffuse = property->GetDiffuse(0);
  params.specular = property->GetSpecular(0);
  params.specular_power = property->GetSpecularPower(0);
  // Cell scalars are constant in each cell, so their gradient is zero wherever it is taken:
  // shading would have no normal to light, and a gradient opacity function would weigh every
  // sample by its value at zero (which usually hides the volume). VTK's unstructured mappers
  // shade nothing and apply no gradient opacity (on point data either); for cell scalars this
  // mapper does the same, with a warning once per change of what it leaves out. Intensity
  // projections use neither.
  CylvolTransfer& transfer = frame.Transfer;
  int ignored = 0;
  if (frame.CellFlag && frame.Blend == CYLVOL_BLEND_COMPOSITE)
  {
    ignored |= params.shading ? 1 : 0;
    ignored |= transfer.gradient_opacity ? 2 : 0;
  }
  if (ignored && ignored != in.CellScalarsIgnored)
  {
    const char* scalarName = frame.Scalars->GetName();
    vtkWarningMacro(<< "The scalars '" << (scalarName ? scalarName : "")
                    << "' are cell data, constant in each cell, with a zero gradient: "
                    << ((ignored & 1) ? "shading" : "")
                    << (ignored == 3 ? " and " : "")
                    << ((ignored & 2) ? "the gradient opacity function" : "")
                    << ((ignored == 3) ? " are" : " is")
                    << " left out, as VTK's unstructured volume mappers leave them out "
                       "(point scalars, e.g. from vtkCellDataToPointData, are shaded).");
  }
  in.CellScalarsIgnored = ignored;
  if (ignored)
  {
    params.shading = 0;
    transfer.gradient_opacity = nullptr;
    transfer.n_gradient_opacity = 0;
  }
  params.early_termination = this->EarlyTermination;
  params.rows_bottom_up = 1;
  params.blend = frame.Blend;
  params.march_reach = this->MarchReach;
  params.max_error = this->MaximumError;
  // Clipping planes (vtkAbstractMapper::AddClippingPlane) in the data's coordinates, where the
  // rays are cast: the side each plane's normal points into is kept. More than cylvol takes
  // are passed on as a count, which cylvol_render refuses with a message (nothing drawn).
  const int planeCount = this->GetNumberOfClippingPlanes();
  params.clip_plane_count = static_cast<uint32_t>(planeCount);
  for (int i = 0; i < std::min(planeCount, static_cast<int>(CYLVOL_MAX_CLIP_PLANES)); ++i)
  {
    this->GetClippingPlaneInDataCoords(vol->GetMatrix(), i, params.clip_planes[i]);
  }
  this->LastSampleDistance = this->SampleDistance;
  if (!(this->SampleDistance > 0.0))
  {
    double step = 0.0;
    if (cylvol_volume_default_step(in.Volume, &step) == CYLVOL_STATUS_OK && step > 0.0)
    {
      this->LastSampleDistance = step * this->RelativeSampleDistance;
      params.step = this->LastSampleDistance;
    }
  }
}

//------------------------------------------------------------------------------
bool vtkCylVolMapper::RenderBands(Frame& frame, vtkRenderer* ren)
{
  vtkInternals& in = *this->Internals;
  vtkRenderWindow* renWin = ren->GetRenderWindow();
  const int width = frame.Width, height = frame.Height;
  // Render in horizontal bands, so that progress can be reported and a pending abort can
  // stop the frame. A band is the full image seen through a projection narrowed to its
  // rows, so every pixel keeps exactly the ray it has in a one-piece render.
  // About 64k pixels a band (4 at 512x512): each cylvol_render call is one parallel job, and
  // more, smaller jobs measurably cost time on two cores.
  const int bands = std::max(1, std::min(8, static_cast<int>(frame.PixelCount / 65536)));
  const double* projectionRows = frame.ProjectionRows;
  CylvolCamera& camera = frame.Camera;
  CylvolRenderParams& params = frame.Params;
  this->UpdateProgress(0.0);
  bool aborted = false;
  for (int b = 0; b < bands; ++b)
  {
    if (renWin->CheckAbortStatus())
    {
      aborted = true;
      break;
    }
    const int r0 = static_cast<int>(static_cast<long long>(height) * b / bands);
    const int r1 = static_cast<int>(static_cast<long long>(height) * (b + 1) / bands);
    if (r1 <= r0)
    {
      continue;
    }
    // NDC rows [lo, hi] of this band mapped onto [-1, 1]: y' = s (y - c).
    const double lo = -1.0 + 2.0 * r0 / height;
    const double hi = -1.0 + 2.0 * r1 / height;
    const double s = 2.0 / (hi - lo);
    const double c = 0.5 * (lo + hi);
    std::copy(projectionRows, projectionRows + 16, camera.projection);
    for (int k = 0; k < 4; ++k)
    {
      camera.projection[4 + k] = s * (projectionRows[4 + k] - c * projectionRows[12 + k]);
    }
    params.height = static_cast<uint32_t>(r1 - r0);
    const size_t offset = static_cast<size_t>(r0) * width;
    const size_t bandPixels = static_cast<size_t>(r1 - r0) * width;
    const CylvolStatus status = cylvol_render(in.Volume, &camera, &frame.Transfer, &params,
      frame.DepthIn ? frame.DepthIn + offset : nullptr, nullptr, CYLVOL_PIXELS_RGBA8,
      in.Tight.data() + 4 * offset, bandPixels * 4);
    if (status != CYLVOL_STATUS_OK)
    {
      const char* detail = cylvol_volume_last_error(in.Volume);
      vtkErrorMacro(<< "cylvol could not render: " << cylvol_status_message(status)
                    << (detail && *detail ? ": " : "") << (detail ? detail : "")
                    << ": nothing drawn.");
      this->ImageSampleDistance = frame.OldImageSampleDistance;
      return false;
    }
    this->AddRenderStatistics();
    this->UpdateProgress(static_cast<double>(b + 1) / bands);
  }
  if (aborted || renWin->GetAbortRender())
  {
    this->ImageSampleDistance = frame.OldImageSampleDistance;
    this->Timer->StopTimer();
    this->LastRenderSeconds = this->Timer->GetElapsedTime();
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::AddRenderStatistics()
{
  CylvolRenderStats rs;
  if (cylvol_volume_render_stats(this->Internals->Volume, &rs) != CYLVOL_STATUS_OK)
  {
    return;
  }
  this->LastRaySeconds += rs.seconds;
  this->LastRays += rs.rays;
  this->LastSamples += rs.samples;
  this->LastSamplesLocated += rs.samples_located;
  this->LastHexTests += rs.hex_tests;
  this->LastInternalVisits += rs.internal_visits;
  this->LastLeafVisits += rs.leaf_visits;
  this->LastGradientEvaluations += rs.gradient_evaluations;
  this->LastEarlyTerminations += rs.early_terminations;
  this->LastSamplesSkipped += rs.samples_skipped;
  this->LastPlaneCertified += rs.plane_certified;
  this->LastWalkSteps += rs.walk_steps;
  this->LastTransparentJumps += rs.transparent_jumps;
  this->LastExtremeSkips += rs.extreme_skips;
  this->LastExtremeJumps += rs.extreme_jumps;
  this->LastFarLocates += rs.far_locates;
  this->LastRefinedSamples += rs.refined_samples;
  this->LastSlopes += rs.slopes;
  this->LastIntegratedStretches += rs.integrated_stretches;
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::Display(Frame& frame, vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& in = *this->Internals;
  const int width = frame.Width, height = frame.Height;
  for (int j = 0; j < height; ++j)
  {
    std::copy(in.Tight.begin() + static_cast<std::ptrdiff_t>(4) * j * width,
      in.Tight.begin() + static_cast<std::ptrdiff_t>(4) * (j + 1) * width,
      in.Image.begin() + static_cast<std::ptrdiff_t>(4) * j * in.ImageMemorySize[0]);
  }
  // The image lies in front of everything drawn at depths behind the volume's nearest
  // bound: the nearest depth of the volume's bounding box (in [0, 1]).
  float depth = -1.0f;
  if (this->IntermixIntersectingGeometry)
  {
    double bounds[6];
    vol->GetBounds(bounds);
    vtkMatrix4x4* composite =
      ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(frame.Aspect, 0, 1);
    double minZ = 1.0;
    for (int k = 0; k < 8; ++k)
    {
      double p[4] = { bounds[k & 1], bounds[2 + ((k >> 1) & 1)], bounds[4 + ((k >> 2) & 1)], 1.0 };
      composite->MultiplyPoint(p, p);
      if (p[3] != 0.0)
      {
        minZ = std::min(minZ, p[2] / p[3]);
      }
    }
    depth = static_cast<float>(vtkMath::ClampValue(minZ, 0.0, 1.0));
  }
  int imageMemorySize[2] = { in.ImageMemorySize[0], in.ImageMemorySize[1] };
  int imageViewportSize[2] = { width, height };
  int imageInUseSize[2] = { width, height };
  int imageOrigin[2] = { 0, 0 };
  if (this->ImageDisplayHelper)
  {
    this->ImageDisplayHelper->RenderTexture(vol, ren, imageMemorySize, imageViewportSize,
      imageInUseSize, imageOrigin, depth, in.Image.data());
  }
  this->Timer->StopTimer();
  this->LastRenderSeconds = this->Timer->GetElapsedTime();
  in.StoreTime(ren, vol, this->LastRenderSeconds);
}

//------------------------------------------------------------------------------
void vtkCylVolMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Structure: " << this->Structure << "\n";
  os << indent << "AxisAuto: " << this->AxisAuto << "\n";
  os << indent << "AxisOrigin: " << this->AxisOrigin[0] << " " << this->AxisOrigin[1] << " "
     << this->AxisOrigin[2] << "\n";
  os << indent << "AxisDirection: " << this->AxisDirection[0] << " " << this->AxisDirection[1]
     << " " << this->AxisDirection[2] << "\n";
  os << indent << "BuildPreset: " << this->BuildPreset << "\n";
  os << indent << "PeriodicCopies: " << this->PeriodicCopies << "\n";
  os << indent << "CopyRange: " << this->CopyRange[0] << " " << this->CopyRange[1] << "\n";
  os << indent << "EarlyTermination: " << this->EarlyTermination << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "RelativeSampleDistance: " << this->RelativeSampleDistance << "\n";
  os << indent << "MarchReach: " << this->MarchReach << "\n";
  os << indent << "MaximumError: " << this->MaximumError << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "MinimumImageSampleDistance: " << this->MinimumImageSampleDistance << "\n";
  os << indent << "MaximumImageSampleDistance: " << this->MaximumImageSampleDistance << "\n";
  os << indent << "AutoAdjustSampleDistances: " << this->AutoAdjustSampleDistances << "\n";
  os << indent << "ScalarComponent: " << this->ScalarComponent << "\n";
  os << indent << "OpacityConvention: " << this->OpacityConvention << "\n";
  os << indent << "IntermixIntersectingGeometry: " << this->IntermixIntersectingGeometry << "\n";
  os << indent << "BuildCount: " << this->BuildCount << "\n";
  os << indent << "ScalarUpdateCount: " << this->ScalarUpdateCount << "\n";
  os << indent << "LastRenderSeconds: " << this->LastRenderSeconds << "\n";
  os << indent << "LastSamples: " << this->LastSamples << "\n";
  os << indent << "LastHexTests: " << this->LastHexTests << "\n";
  os << indent << "LastSamplesSkipped: " << this->LastSamplesSkipped << "\n";
  os << indent << "LastPlaneCertified: " << this->LastPlaneCertified << "\n";
  os << indent << "LastWalkSteps: " << this->LastWalkSteps << "\n";
  os << indent << "LastTransparentJumps: " << this->LastTransparentJumps << "\n";
  os << indent << "LastExtremeSkips: " << this->LastExtremeSkips << "\n";
  os << indent << "LastExtremeJumps: " << this->LastExtremeJumps << "\n";
  os << indent << "LastFarLocates: " << this->LastFarLocates << "\n";
  os << indent << "LastRefinedSamples: " << this->LastRefinedSamples << "\n";
  os << indent << "LastSlopes: " << this->LastSlopes << "\n";
  os << indent << "LastIntegratedStretches: " << this->LastIntegratedStretches << "\n";
}
