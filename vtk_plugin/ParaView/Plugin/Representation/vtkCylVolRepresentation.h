/**
 * @class   vtkCylVolRepresentation
 * @brief   ParaView's "CylVol Volume": volume rendering of hexahedral meshes with cylvol
 *
 * vtkCylVolRepresentation draws the volume cells of its input (an unstructured or structured
 * grid, or a multiblock or partitioned dataset of them: see CylVolVolumeCells.h) with
 * vtkCylVolMapper, as they are: hexahedra stay hexahedra. It shares the standard volume
 * representation's colour and opacity transfer functions, scalar opacity unit distance and
 * lighting, and adds cylvol's own settings (structure, machine axis, sample distance, early
 * termination, image sample distance).
 *
 * Distributed (pvserver, pvbatch over MPI), it asks the render view for ordered compositing
 * with its data redistributable and used for load balancing: ParaView's k-d tree gives each
 * rank a box, the cells crossing a box's faces go to every rank whose box they cross, and
 * each rank's rays are cut at its box's inner faces by the mapper's clipping planes, so that
 * every rank draws exactly the part of the volume in its box and IceT blends the ranks'
 * images in visibility order. The structure, the machine axis and the default sample
 * distance are chosen once for the whole dataset (CylVolWholeDataset.h), so that every rank
 * draws with the same ones.
 */
#ifndef vtkCylVolRepresentation_h
#define vtkCylVolRepresentation_h

#include "vtkCylVolParaViewModule.h" // for export macro
#include "vtkNew.h"                  // for vtkNew
#include "vtkSmartPointer.h"         // for vtkSmartPointer
#include "vtkVolumeRepresentation.h"

#include <string> // for std::string

class vtkCylVolMapper;
class vtkDataObject;
class vtkPolyDataMapper;
class vtkPVGeometryFilter;
class vtkPVRenderView;
class vtkUnstructuredGrid;

class VTKCYLVOLPARAVIEW_EXPORT vtkCylVolRepresentation : public vtkVolumeRepresentation
{
public:
  static vtkCylVolRepresentation* New();
  vtkTypeMacro(vtkCylVolRepresentation, vtkVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int ProcessViewRequest(vtkInformationRequestKey* request_type, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  ///@{
  /**
   * cylvol's settings (vtkCylVolMapper's of the same names). The structure (0 auto, 1
   * Cartesian grid, 2 cylindrical grid, 3 Cartesian BVH, 4 cylindrical BVH) and the axis
   * (detected when AxisAuto is on) are chosen for the whole dataset. SampleDistance 0 (the
   * default) takes cylvol's default step for the whole dataset. MaximumError 0 (the default)
   * samples every sample distance; above 0 it is the largest colour error allowed, in 1/255
   * of a pixel, against the converged image, the sample distance then the step each ray
   * starts with (under MPI each rank holds its own part of a ray to it).
   */
  void SetStructure(int structure);
  vtkGetMacro(Structure, int);
  void SetAxisAuto(int value);
  vtkGetMacro(AxisAuto, int);
  void SetAxisOrigin(double x, double y, double z);
  vtkGetVector3Macro(AxisOrigin, double);
  void SetAxisDirection(double x, double y, double z);
  vtkGetVector3Macro(AxisDirection, double);
  void SetSampleDistance(double distance);
  vtkGetMacro(SampleDistance, double);
  void SetMaximumError(double value);
  vtkGetMacro(MaximumError, double);
  void SetEarlyTermination(double value);
  void SetImageSampleDistance(double value);
  ///@}

  ///@{
  /**
   * Periodic copies (vtkCylVolMapper's PeriodicCopies and CopyRange): 0 draws the input as it
   * is, -1 finds how many copies of the sector close the wheel, N draws N copies; CopyRange
   * (first, end) draws some of them (0 0: all). The view's bounds are the wheel's. Drawn in
   * one process only (a builtin session, pvpython, pvbatch or one pvserver rank): under MPI
   * each rank's box holds its part of the sector, not of the wheel, so the sector is drawn
   * as it is, with an error saying so.
   */
  void SetPeriodicCopies(int copies);
  vtkGetMacro(PeriodicCopies, int);
  void SetCopyRange(int first, int end);
  vtkGetVector2Macro(CopyRange, int);
  ///@}

  ///@{
  /**
   * Lighting, forwarded to the volume property.
   */
  void SetShade(int value);
  void SetAmbient(double value);
  void SetDiffuse(double value);
  void SetSpecular(double value);
  void SetSpecularPower(double value);
  ///@}

  ///@{
  /**
   * What the last render did on this process (ParaView's information properties; under MPI
   * each rank has its own):
   * - BuiltStructure: the structure built (vtkCylVolMapper::StructureType), -1 before any.
   * - GetBuiltAxis: the axis it was built about (origin, then direction).
   * - GetCellTypeCounts: the cells handed to cylvol by type: hexahedra, voxels, wedges,
   *   pyramids, tetrahedra.
   * - GetPieceBox: the box this rank's rays were cut to (xmin, xmax, ...); an empty box
   *   (min > max) when they were not cut.
   * - GetRenderStatistics: the cells of the piece drawn, the clipping planes cutting it, the
   *   structure builds so far, the last render's seconds, its samples, and the sample
   *   distance used.
   * - GetWholeDataset: the whole dataset's cells, the cells sampled from it, its default
   *   step (0 when there was nothing to sample), and the volume cells this rank's input held
   *   (before the view moved any between ranks).
   * - GetErrorBounded: the mapper's MaximumError, and the last render's refined samples,
   *   slopes and integrated stretches (all 0 at the fixed step).
   */
  int GetBuiltStructure();
  double* GetBuiltAxis() VTK_SIZEHINT(6);
  double* GetCellTypeCounts() VTK_SIZEHINT(5);
  double* GetPieceBox() VTK_SIZEHINT(6);
  double* GetRenderStatistics() VTK_SIZEHINT(6);
  double* GetWholeDataset() VTK_SIZEHINT(4);
  double* GetErrorBounded() VTK_SIZEHINT(4);
  ///@}

  /**
   * The periodic copies of the last build: how many close the wheel (0 where none are
   * drawn), then the first and one past the last copy drawn.
   */
  int* GetBuiltPeriodicCopies() VTK_SIZEHINT(3);

  /**
   * The mapper that draws the volume.
   */
  vtkCylVolMapper* GetCylVolMapper();

protected:
  vtkCylVolRepresentation();
  ~vtkCylVolRepresentation() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

  int Structure = 0;
  int AxisAuto = 1;
  double AxisOrigin[3] = { 0.0, 0.0, 0.0 };
  double AxisDirection[3] = { 0.0, 0.0, 1.0 };
  double SampleDistance = 0.0;
  double MaximumError = 0.0;
  int PeriodicCopies = 0;
  int CopyRange[2] = { 0, 0 };

private:
  vtkCylVolRepresentation(const vtkCylVolRepresentation&) = delete;
  void operator=(const vtkCylVolRepresentation&) = delete;

  // The steps of RequestData: this rank's volume cells (empty when the whole dataset is to
  // draw nothing, with the error saying why), and the whole dataset's structure, axis and
  // step (collective over the ranks).
  vtkSmartPointer<vtkUnstructuredGrid> GatherVolumeCells(vtkDataObject* input);
  void ChooseForWholeDataset();

  // The steps of REQUEST_RENDER: the piece this rank draws, the box its rays are cut to, and
  // the mapper's settings.
  void SelectRenderPiece(vtkInformation* inInfo);
  void CutToRankBox(vtkPVRenderView* view);
  void UpdateMapperParameters();

  vtkNew<vtkCylVolMapper> Mapper;
  vtkNew<vtkPVGeometryFilter> LODGeometryFilter;
  vtkNew<vtkPolyDataMapper> LODMapper;

  class vtkInternals;
  vtkInternals* Internals;
};

#endif
