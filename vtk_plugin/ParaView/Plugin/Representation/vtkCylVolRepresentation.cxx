// ParaView's "CylVol Volume" representation: the input's volume cells, untouched, drawn by
// vtkCylVolMapper; distributed through the render view's ordered compositing (see the header).
#include "vtkCylVolRepresentation.h"

#include "CylVolVolumeCells.h"
#include "CylVolWholeDataset.h"

#include "vtkAlgorithmOutput.h"
#include "vtkBoundingBox.h"
#include "vtkCellData.h"
#include "vtkColorTransferFunction.h"
#include "vtkCylVolMapper.h"
#include "vtkDataSetAttributes.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPVGeometryFilter.h"
#include "vtkPVLODVolume.h"
#include "vtkPVRenderView.h"
#include "vtkPVRenderViewDataDeliveryManager.h"
#include "vtkPlane.h"
#include "vtkPointData.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderer.h"
#include "vtkUnstructuredGrid.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkCylVolRepresentation);

namespace
{
vtkMultiProcessController* Ranks()
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return controller && controller->GetNumberOfProcesses() > 1 ? controller : nullptr;
}

// The box of the cylinder about the axis (origin, direction) that holds every copy of the
// grid's points turned about it: the wheel a periodic sector makes.
void WheelBounds(vtkDataSet* grid, const double origin[3], const double direction[3],
  double bounds[6])
{
  double axis[3] = { direction[0], direction[1], direction[2] };
  const double length = vtkMath::Normalize(axis);
  if (!(length > 0.0))
  {
    return;
  }
  double radius = 0.0, h0 = VTK_DOUBLE_MAX, h1 = -VTK_DOUBLE_MAX;
  for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
  {
    double p[3];
    grid->GetPoint(i, p);
    double d[3] = { p[0] - origin[0], p[1] - origin[1], p[2] - origin[2] };
    const double h = vtkMath::Dot(d, axis);
    for (int k = 0; k < 3; ++k)
    {
      d[k] -= h * axis[k];
    }
    radius = std::max(radius, vtkMath::Norm(d));
    h0 = std::min(h0, h);
    h1 = std::max(h1, h);
  }
  for (int k = 0; k < 3; ++k)
  {
    const double a = origin[k] + h0 * axis[k], b = origin[k] + h1 * axis[k];
    const double half = radius * std::sqrt(std::max(0.0, 1.0 - axis[k] * axis[k]));
    bounds[2 * k] = std::min(a, b) - half;
    bounds[2 * k + 1] = std::max(a, b) + half;
  }
}

// The sums over all ranks of `values` (this process's alone without MPI).
std::vector<double> SumOverRanks(std::vector<double> values)
{
  if (vtkMultiProcessController* controller = Ranks())
  {
    std::vector<double> sums(values.size(), 0.0);
    controller->AllReduce(
      values.data(), sums.data(), static_cast<vtkIdType>(values.size()), vtkCommunicator::SUM_OP);
    return sums;
  }
  return values;
}
// Under MPI, numbers the grid's points with ids unique over all ranks (this rank's after the
// points of the ranks before it), as its global point ids. When the view redistributes the
// cells, it merges the points each rank receives by these ids: a point that several ranks
// send is one point again, and points that merely coincide (the two faces of a slit or
// baffle, blocks that touch) stay apart, as cylvol has them on one rank.
void NumberPointsGlobally(vtkUnstructuredGrid* grid)
{
  vtkMultiProcessController* controller = Ranks();
  if (!controller)
  {
    return;
  }
  const vtkIdType count = grid->GetNumberOfPoints();
  vtkIdType first = 0;
  std::vector<vtkIdType> counts(static_cast<size_t>(controller->GetNumberOfProcesses()), 0);
  controller->AllGather(&count, counts.data(), 1);
  for (int r = 0; r < controller->GetLocalProcessId(); ++r)
  {
    first += counts[static_cast<size_t>(r)];
  }
  vtkNew<vtkIdTypeArray> ids;
  ids->SetName("CylVolPointIds");
  ids->SetNumberOfTuples(count);
  for (vtkIdType i = 0; i < count; ++i)
  {
    ids->SetValue(i, first + i);
  }
  grid->GetPointData()->SetGlobalIds(ids);
}
} // namespace

//------------------------------------------------------------------------------
class vtkCylVolRepresentation::vtkInternals
{
public:
  // This rank's volume cells, as the input gave them (before any redistribution), and whether
  // the whole dataset is to draw nothing (cells cylvol does not take, or no volume at all).
  vtkSmartPointer<vtkUnstructuredGrid> VolumeCells;
  bool DrawNothing = false;
  cylvolpv::WholeDatasetChoice Choice;

  // The piece this rank draws: the view's piece (redistributed under ordered compositing)
  // without its ghost array, which then only says which rank owns each duplicated boundary
  // cell; every rank draws those cells, cut to its own box. Remade when the view's piece
  // changes.
  vtkDataObject* RenderSource = nullptr; // compared only
  vtkMTimeType RenderSourceMTime = 0;
  vtkSmartPointer<vtkUnstructuredGrid> RenderPiece;

  double EarlyTermination = 0.99;
  double ImageSampleDistance = 1.0;
  bool WarnedNoArray = false;

  // The box this rank's rays are cut to, and how many of its faces cut them.
  double PieceBox[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  int ClipPlanes = 0;

  // Storage for the information getters.
  double BuiltAxis[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  double CellTypeCounts[5] = { 0.0, 0.0, 0.0, 0.0, 0.0 };
  double RenderStatistics[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  double WholeDataset[4] = { 0.0, 0.0, 0.0, 0.0 };
  double ErrorBounded[4] = { 0.0, 0.0, 0.0, 0.0 };
  int BuiltPeriodicCopies[3] = { 0, 0, 0 };
};

//------------------------------------------------------------------------------
vtkCylVolRepresentation::vtkCylVolRepresentation()
  : Internals(new vtkInternals)
{
  this->Internals->VolumeCells = vtkSmartPointer<vtkUnstructuredGrid>::New();
  this->LODGeometryFilter->SetUseOutline(0);
  this->Actor->SetLODMapper(this->LODMapper);
}

//------------------------------------------------------------------------------
vtkCylVolRepresentation::~vtkCylVolRepresentation()
{
  delete this->Internals;
}

//------------------------------------------------------------------------------
vtkCylVolMapper* vtkCylVolRepresentation::GetCylVolMapper()
{
  return this->Mapper;
}

//------------------------------------------------------------------------------
int vtkCylVolRepresentation::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkCompositeDataSet");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkCylVolRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInternals& in = *this->Internals;
  vtkMath::UninitializeBounds(this->DataBounds);
  this->DataSize = 0;
  vtkDataObject* input = inputVector[0]->GetNumberOfInformationObjects() == 1
    ? vtkDataObject::GetData(inputVector[0], 0)
    : nullptr;
  in.VolumeCells = this->GatherVolumeCells(input);
  NumberPointsGlobally(in.VolumeCells);
  this->ChooseForWholeDataset();
  if (in.VolumeCells->GetNumberOfCells() > 0)
  {
    in.VolumeCells->GetBounds(this->DataBounds);
    this->DataSize = in.VolumeCells->GetActualMemorySize();
  }
  if (this->PeriodicCopies != 0)
  {
    vtkMultiProcessController* ranks = Ranks();
    if (ranks && ranks->GetLocalProcessId() == 0)
    {
      vtkErrorMacro(<< "Periodic copies are drawn in one process only (a builtin session, "
                       "pvpython, pvbatch or one pvserver rank); over "
                    << ranks->GetNumberOfProcesses()
                    << " ranks each rank's box holds its part of the sector, not of the wheel: "
                       "the sector is drawn as it is.");
    }
    else if (!ranks && in.Choice.Valid && in.VolumeCells->GetNumberOfCells() > 0)
    {
      WheelBounds(in.VolumeCells, in.Choice.AxisOrigin, in.Choice.AxisDirection, this->DataBounds);
    }
  }
  return this->Superclass::RequestData(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkUnstructuredGrid> vtkCylVolRepresentation::GatherVolumeCells(
  vtkDataObject* input)
{
  cylvolpv::VolumeCells cells = cylvolpv::GatherVolumeCells(input);
  if (!cells.Unsupported.empty())
  {
    vtkErrorMacro(<< "The input has volume cells that CylVol Volume does not draw: "
                  << cells.Unsupported
                  << ". It draws hexahedra, voxels, wedges, pyramids and tetrahedra: nothing "
                     "drawn.");
  }
  // Whether any rank has cells it cannot draw, and whether the dataset has a volume at all:
  // the whole dataset is drawn, or nothing.
  const std::vector<double> totals =
    SumOverRanks({ cells.Unsupported.empty() ? 0.0 : 1.0,
      static_cast<double>(cells.Grid->GetNumberOfCells()), static_cast<double>(cells.InputCells) });
  vtkMultiProcessController* ranks = Ranks();
  if (totals[1] == 0.0 && totals[2] > 0.0 && (!ranks || ranks->GetLocalProcessId() == 0))
  {
    vtkErrorMacro(<< "The input (" << (input ? input->GetClassName() : "none")
                  << ") has no volume cells, only surfaces, lines or points; CylVol Volume "
                     "draws volume meshes (hexahedra, voxels, wedges, pyramids, tetrahedra): "
                     "nothing drawn.");
  }
  this->Internals->DrawNothing = totals[0] > 0.0 || totals[1] == 0.0;
  return this->Internals->DrawNothing ? vtkSmartPointer<vtkUnstructuredGrid>::New() : cells.Grid;
}

//------------------------------------------------------------------------------
void vtkCylVolRepresentation::ChooseForWholeDataset()
{
  vtkInternals& in = *this->Internals;
  if (in.DrawNothing)
  {
    in.Choice = cylvolpv::WholeDatasetChoice();
    return;
  }
  cylvolpv::WholeDatasetRequest wanted;
  wanted.Structure = this->Structure;
  wanted.AxisAuto = this->AxisAuto != 0;
  std::copy(this->AxisOrigin, this->AxisOrigin + 3, wanted.AxisOrigin);
  std::copy(this->AxisDirection, this->AxisDirection + 3, wanted.AxisDirection);
  vtkMultiProcessController* ranks = Ranks();
  in.Choice = cylvolpv::ChooseForWholeDataset(in.VolumeCells, wanted, ranks);
  if (!in.Choice.Valid && (!ranks || ranks->GetLocalProcessId() == 0))
  {
    vtkWarningMacro(<< "No whole-dataset structure, axis and step (" << in.Choice.Problem
                    << "); each rank's mapper chooses its own.");
  }
}

//------------------------------------------------------------------------------
int vtkCylVolRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* request_type, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(request_type, inInfo, outInfo))
  {
    return 0;
  }
  if (request_type == vtkPVView::REQUEST_UPDATE())
  {
    outInfo->Set(vtkPVRenderView::NEED_ORDERED_COMPOSITING(), 1);
    vtkPVRenderView::SetPiece(inInfo, this, this->Internals->VolumeCells, this->DataSize);
    // The view may move the cells between ranks, and builds its k-d tree from them; cells
    // crossing a box's faces go to every rank whose box they cross (each cuts its rays there).
    vtkPVRenderView::SetOrderedCompositingConfiguration(inInfo, this,
      vtkPVRenderView::DATA_IS_REDISTRIBUTABLE | vtkPVRenderView::USE_DATA_FOR_LOAD_BALANCING);
    vtkPVRenderView::SetRedistributionModeToDuplicateBoundaryCells(inInfo, this);
    vtkPVRenderView::SetRequiresDistributedRendering(inInfo, this, true);
    vtkNew<vtkMatrix4x4> matrix;
    this->Actor->GetMatrix(matrix);
    vtkPVRenderView::SetGeometryBounds(inInfo, this, this->DataBounds, matrix);
    this->Actor->SetMapper(nullptr);
  }
  else if (request_type == vtkPVView::REQUEST_UPDATE_LOD())
  {
    this->LODGeometryFilter->SetInputData(vtkPVView::GetPiece(inInfo, this));
    this->LODGeometryFilter->SetUseOutline(
      inInfo->Has(vtkPVRenderView::USE_OUTLINE_FOR_LOD()) ? 1 : 0);
    this->LODGeometryFilter->Update();
    vtkPVRenderView::SetPieceLOD(inInfo, this, this->LODGeometryFilter->GetOutputDataObject(0));
  }
  else if (request_type == vtkPVView::REQUEST_RENDER())
  {
    this->Actor->SetEnableLOD(inInfo->Has(vtkPVRenderView::USE_LOD()) ? 1 : 0);
    this->SelectRenderPiece(inInfo);
    this->CutToRankBox(vtkPVRenderView::SafeDownCast(inInfo->Get(vtkPVView::VIEW())));
    this->UpdateMapperParameters();
    this->LODMapper->SetInputConnection(vtkPVRenderView::GetPieceProducerLOD(inInfo, this));
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkCylVolRepresentation::SelectRenderPiece(vtkInformation* inInfo)
{
  vtkInternals& in = *this->Internals;
  vtkAlgorithmOutput* port = vtkPVRenderView::GetPieceProducer(inInfo, this);
  vtkUnstructuredGrid* source = port
    ? vtkUnstructuredGrid::SafeDownCast(port->GetProducer()->GetOutputDataObject(port->GetIndex()))
    : nullptr;
  if (!source)
  {
    in.RenderSource = nullptr;
    in.RenderPiece = nullptr;
    return;
  }
  if (source == in.RenderSource && source->GetMTime() == in.RenderSourceMTime && in.RenderPiece)
  {
    return;
  }
  in.RenderSource = source;
  in.RenderSourceMTime = source->GetMTime();
  in.RenderPiece = vtkSmartPointer<vtkUnstructuredGrid>::New();
  in.RenderPiece->ShallowCopy(source);
  in.RenderPiece->GetCellData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
}

//------------------------------------------------------------------------------
void vtkCylVolRepresentation::CutToRankBox(vtkPVRenderView* view)
{
  vtkInternals& in = *this->Internals;
  vtkMath::UninitializeBounds(in.PieceBox);
  in.PieceBox[0] = in.PieceBox[2] = in.PieceBox[4] = 1.0;
  in.PieceBox[1] = in.PieceBox[3] = in.PieceBox[5] = -1.0;
  in.ClipPlanes = 0;
  this->Mapper->RemoveAllClippingPlanes();
  vtkMultiProcessController* controller = Ranks();
  auto delivery = view
    ? vtkPVRenderViewDataDeliveryManager::SafeDownCast(view->GetDeliveryManager())
    : nullptr;
  if (!controller || !delivery || !view->GetUseOrderedCompositing())
  {
    return;
  }
  const std::vector<vtkBoundingBox>& cuts = delivery->GetCuts();
  const int rank = controller->GetLocalProcessId();
  if (rank >= static_cast<int>(cuts.size()) || !cuts[rank].IsValid())
  {
    return;
  }
  vtkBoundingBox whole;
  for (const vtkBoundingBox& cut : cuts)
  {
    whole.AddBox(cut);
  }
  cuts[rank].GetBounds(in.PieceBox);
  double outer[6];
  whole.GetBounds(outer);
  // The box's faces inside the whole domain cut the rays, each keeping the box's side; the
  // planes are the data's, carried into the world by the volume's matrix as the mapper wants.
  vtkNew<vtkMatrix4x4> matrix;
  this->Actor->GetMatrix(matrix);
  vtkNew<vtkMatrix4x4> normalMatrix;
  vtkMatrix4x4::Invert(matrix, normalMatrix);
  normalMatrix->Transpose();
  for (int face = 0; face < 6; ++face)
  {
    const int axis = face / 2;
    const bool low = face % 2 == 0;
    const bool inner = low ? in.PieceBox[face] > outer[face] : in.PieceBox[face] < outer[face];
    if (!inner)
    {
      continue;
    }
    double origin[4] = { 0.0, 0.0, 0.0, 1.0 };
    double normal[4] = { 0.0, 0.0, 0.0, 0.0 };
    origin[axis] = in.PieceBox[face];
    normal[axis] = low ? 1.0 : -1.0;
    matrix->MultiplyPoint(origin, origin);
    normalMatrix->MultiplyPoint(normal, normal);
    vtkNew<vtkPlane> plane;
    plane->SetOrigin(origin[0] / origin[3], origin[1] / origin[3], origin[2] / origin[3]);
    plane->SetNormal(normal[0], normal[1], normal[2]);
    this->Mapper->AddClippingPlane(plane);
    in.ClipPlanes++;
  }
}

//------------------------------------------------------------------------------
void vtkCylVolRepresentation::UpdateMapperParameters()
{
  vtkInternals& in = *this->Internals;
  vtkCylVolMapper* mapper = this->Mapper;
  const char* arrayName = nullptr;
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  vtkInformation* info = this->GetInputArrayInformation(0);
  if (info && info->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    info->Has(vtkDataObject::FIELD_NAME()))
  {
    arrayName = info->Get(vtkDataObject::FIELD_NAME());
    association = info->Get(vtkDataObject::FIELD_ASSOCIATION());
  }
  mapper->SelectScalarArray(arrayName);
  mapper->SetScalarMode(association == vtkDataObject::FIELD_ASSOCIATION_CELLS
      ? VTK_SCALAR_MODE_USE_CELL_FIELD_DATA
      : VTK_SCALAR_MODE_USE_POINT_FIELD_DATA);
  this->LODMapper->SetScalarVisibility(arrayName && arrayName[0] ? 1 : 0);
  this->LODMapper->SelectColorArray(arrayName);
  this->LODMapper->SetScalarMode(association == vtkDataObject::FIELD_ASSOCIATION_CELLS
      ? VTK_SCALAR_MODE_USE_CELL_FIELD_DATA
      : VTK_SCALAR_MODE_USE_POINT_FIELD_DATA);

  // One component (the colour map's, as ParaView's volume representations take it) through
  // the property's first transfer functions.
  this->Property->SetIndependentComponents(this->MapScalars && !this->MultiComponentsMapping);
  vtkColorTransferFunction* ctf = this->Property->GetRGBTransferFunction(0);
  mapper->SetScalarComponent(ctf && ctf->GetVectorMode() == vtkScalarsToColors::COMPONENT
      ? ctf->GetVectorComponent()
      : vtkCylVolMapper::SCALAR_MAGNITUDE);

  const cylvolpv::WholeDatasetChoice& choice = in.Choice;
  if (choice.Valid)
  {
    mapper->SetStructure(choice.Structure);
    mapper->AxisAutoOff();
    mapper->SetAxisOrigin(choice.AxisOrigin);
    mapper->SetAxisDirection(choice.AxisDirection);
  }
  else
  {
    mapper->SetStructure(this->Structure);
    mapper->SetAxisAuto(this->AxisAuto);
    mapper->SetAxisOrigin(this->AxisOrigin);
    mapper->SetAxisDirection(this->AxisDirection);
  }
  mapper->SetSampleDistance(this->SampleDistance > 0.0 ? this->SampleDistance
      : choice.Valid                                    ? choice.DefaultStep
                                                        : 0.0);
  mapper->SetMaximumError(this->MaximumError);
  mapper->SetPeriodicCopies(Ranks() ? 0 : this->PeriodicCopies);
  mapper->SetCopyRange(this->CopyRange[0], this->CopyRange[1]);
  mapper->SetEarlyTermination(in.EarlyTermination);
  mapper->SetImageSampleDistance(static_cast<float>(in.ImageSampleDistance));

  const bool noArray = !arrayName || !arrayName[0];
  if (noArray && !in.WarnedNoArray && in.VolumeCells->GetNumberOfCells() > 0)
  {
    vtkWarningMacro(<< "CylVol Volume draws a point or cell array through the colour and "
                       "opacity maps: colour by an array to see the volume.");
  }
  in.WarnedNoArray = noArray;
  const bool draws = !in.DrawNothing && !noArray && in.RenderPiece &&
    in.RenderPiece->GetNumberOfCells() > 0;
  if (draws)
  {
    mapper->SetInputData(in.RenderPiece);
  }
  this->Actor->SetMapper(draws ? mapper : nullptr);
}

//------------------------------------------------------------------------------
bool vtkCylVolRepresentation::AddToView(vtkView* view)
{
  vtkPVRenderView* renderView = vtkPVRenderView::SafeDownCast(view);
  if (!renderView)
  {
    return false;
  }
  renderView->GetRenderer()->AddActor(this->Actor);
  return this->Superclass::AddToView(view);
}

//------------------------------------------------------------------------------
bool vtkCylVolRepresentation::RemoveFromView(vtkView* view)
{
  vtkPVRenderView* renderView = vtkPVRenderView::SafeDownCast(view);
  if (!renderView)
  {
    return false;
  }
  renderView->GetRenderer()->RemoveActor(this->Actor);
  return this->Superclass::RemoveFromView(view);
}

//------------------------------------------------------------------------------
// The structure and axis settings feed the whole dataset's choice (RequestData).
void vtkCylVolRepresentation::SetStructure(int structure)
{
  if (structure != this->Structure)
  {
    this->Structure = structure;
    this->MarkModified();
  }
}

void vtkCylVolRepresentation::SetAxisAuto(int value)
{
  if (value != this->AxisAuto)
  {
    this->AxisAuto = value;
    this->MarkModified();
  }
}

void vtkCylVolRepresentation::SetAxisOrigin(double x, double y, double z)
{
  if (x != this->AxisOrigin[0] || y != this->AxisOrigin[1] || z != this->AxisOrigin[2])
  {
    this->AxisOrigin[0] = x;
    this->AxisOrigin[1] = y;
    this->AxisOrigin[2] = z;
    this->MarkModified();
  }
}

void vtkCylVolRepresentation::SetAxisDirection(double x, double y, double z)
{
  if (x != this->AxisDirection[0] || y != this->AxisDirection[1] || z != this->AxisDirection[2])
  {
    this->AxisDirection[0] = x;
    this->AxisDirection[1] = y;
    this->AxisDirection[2] = z;
    this->MarkModified();
  }
}

// The mapper's own settings: handed over at the next render, without updating the data.
void vtkCylVolRepresentation::SetSampleDistance(double distance)
{
  this->SampleDistance = distance;
}

void vtkCylVolRepresentation::SetMaximumError(double value)
{
  this->MaximumError = value;
}

void vtkCylVolRepresentation::SetPeriodicCopies(int copies)
{
  if (copies != this->PeriodicCopies)
  {
    this->PeriodicCopies = copies;
    this->MarkModified(); // the view's bounds are the wheel's
  }
}

void vtkCylVolRepresentation::SetCopyRange(int first, int end)
{
  this->CopyRange[0] = first;
  this->CopyRange[1] = end;
}

void vtkCylVolRepresentation::SetEarlyTermination(double value)
{
  this->Internals->EarlyTermination = value;
}

void vtkCylVolRepresentation::SetImageSampleDistance(double value)
{
  this->Internals->ImageSampleDistance = value;
}

void vtkCylVolRepresentation::SetShade(int value)
{
  this->Property->SetShade(value);
}

void vtkCylVolRepresentation::SetAmbient(double value)
{
  this->Property->SetAmbient(value);
}

void vtkCylVolRepresentation::SetDiffuse(double value)
{
  this->Property->SetDiffuse(value);
}

void vtkCylVolRepresentation::SetSpecular(double value)
{
  this->Property->SetSpecular(value);
}

void vtkCylVolRepresentation::SetSpecularPower(double value)
{
  this->Property->SetSpecularPower(value);
}

//------------------------------------------------------------------------------
int vtkCylVolRepresentation::GetBuiltStructure()
{
  return this->Mapper->GetBuiltStructure();
}

int* vtkCylVolRepresentation::GetBuiltPeriodicCopies()
{
  int* copies = this->Internals->BuiltPeriodicCopies;
  copies[0] = this->Mapper->GetBuiltPeriodicCopies();
  this->Mapper->GetBuiltCopyRange(copies + 1);
  return copies;
}

double* vtkCylVolRepresentation::GetBuiltAxis()
{
  double* axis = this->Internals->BuiltAxis;
  this->Mapper->GetBuiltAxisOrigin(axis);
  this->Mapper->GetBuiltAxisDirection(axis + 3);
  return axis;
}

double* vtkCylVolRepresentation::GetCellTypeCounts()
{
  const int types[5] = { VTK_HEXAHEDRON, VTK_VOXEL, VTK_WEDGE, VTK_PYRAMID, VTK_TETRA };
  for (int i = 0; i < 5; ++i)
  {
    this->Internals->CellTypeCounts[i] =
      static_cast<double>(this->Mapper->GetBuiltCellCount(types[i]));
  }
  return this->Internals->CellTypeCounts;
}

double* vtkCylVolRepresentation::GetPieceBox()
{
  return this->Internals->PieceBox;
}

double* vtkCylVolRepresentation::GetRenderStatistics()
{
  vtkInternals& in = *this->Internals;
  in.RenderStatistics[0] = in.RenderPiece ? static_cast<double>(in.RenderPiece->GetNumberOfCells()) : 0.0;
  in.RenderStatistics[1] = in.ClipPlanes;
  in.RenderStatistics[2] = this->Mapper->GetBuildCount();
  in.RenderStatistics[3] = this->Mapper->GetLastRenderSeconds();
  in.RenderStatistics[4] = static_cast<double>(this->Mapper->GetLastSamples());
  in.RenderStatistics[5] = this->Mapper->GetLastSampleDistance();
  return in.RenderStatistics;
}

double* vtkCylVolRepresentation::GetWholeDataset()
{
  vtkInternals& in = *this->Internals;
  in.WholeDataset[0] = in.Choice.TotalCells;
  in.WholeDataset[1] = in.Choice.SampledCells;
  in.WholeDataset[2] = in.Choice.Valid ? in.Choice.DefaultStep : 0.0;
  in.WholeDataset[3] = static_cast<double>(in.VolumeCells->GetNumberOfCells());
  return in.WholeDataset;
}

double* vtkCylVolRepresentation::GetErrorBounded()
{
  double* e = this->Internals->ErrorBounded;
  e[0] = this->Mapper->GetMaximumError();
  e[1] = static_cast<double>(this->Mapper->GetLastRefinedSamples());
  e[2] = static_cast<double>(this->Mapper->GetLastSlopes());
  e[3] = static_cast<double>(this->Mapper->GetLastIntegratedStretches());
  return e;
}

//------------------------------------------------------------------------------
void vtkCylVolRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Structure: " << this->Structure << "\n";
  os << indent << "AxisAuto: " << this->AxisAuto << "\n";
  os << indent << "AxisOrigin: " << this->AxisOrigin[0] << " " << this->AxisOrigin[1] << " "
     << this->AxisOrigin[2] << "\n";
  os << indent << "AxisDirection: " << this->AxisDirection[0] << " " << this->AxisDirection[1]
     << " " << this->AxisDirection[2] << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "MaximumError: " << this->MaximumError << "\n";
}
