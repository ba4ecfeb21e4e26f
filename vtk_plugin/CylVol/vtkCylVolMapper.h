/**
 * @class   vtkCylVolMapper
 * @brief   ray casts unstructured hexahedral grids on the CPU with the cylvol library
 *
 * vtkCylVolMapper is a vtkUnstructuredGridVolumeMapper for large hexahedral CFD meshes
 * (pumps, turbines, combustors). It hands the grid to cylvol once, which builds an
 * acceleration structure (a two-level grid or a BVH, in Cartesian or cylindrical
 * coordinates about the machine's axis), and keeps that structure across frames: it is
 * rebuilt only when the grid's points or cells, or the structure settings, change. When
 * only the scalars change (new values, another array, another component), the new
 * values are handed over without a rebuild.
 *
 * Cells: hexahedron, voxel, wedge, pyramid and tetrahedron. Any other cell type, missing
 * or unusable scalars, or an empty grid is reported with vtkErrorMacro and nothing is
 * drawn.
 *
 * The mapper honours vtkVolumeProperty (RGB or gray colour, scalar opacity and its unit
 * distance, shading with ambient/diffuse/specular/specular power, gradient opacity when
 * one is set and enabled, nearest or linear interpolation), the mapper's scalar mode and
 * SelectScalarArray, the volume's matrix, perspective and parallel cameras (the volume is
 * drawn between the camera's near and far clipping planes), viewports, the depth of opaque
 * geometry already drawn, and up to six clipping planes
 * (AddClippingPlane: the volume on the side each plane's normal points to is drawn, and it
 * ends exactly on the plane; more planes are an error and nothing is drawn).
 *
 * Shading and gradient opacity apply to point scalars. Cell scalars are constant in each cell
 * (their gradient is zero), so for them both are left out, as VTK's unstructured mappers
 * always leave them out, with a warning (once per change of what is left out).
 *
 * Blend modes: compositing (the default), SetBlendModeToMaximumIntensity() and
 * SetBlendModeToMinimumIntensity() (vtkVolumeMapper's value 2). A projection shows the colour
 * of the largest (smallest) scalar sampled on each ray with the opacity of one unit distance
 * there (read by the opacity convention below); it shades nothing, applies no gradient opacity
 * and does not stop rays early. Any other blend mode is an error and nothing is drawn.
 *
 * Error-bounded rendering: SetMaximumError(E) with E above 0 keeps each pixel within E/255 of
 * the converged image (what the samples approach as they get denser), compositing with
 * samples placed along each ray where the field and the transfer function need them; 0 (the
 * default) samples every sample distance.
 *
 * Opacity convention: by default the scalar opacity is read the way
 * vtkUnstructuredGridVolumeRayCastMapper reads it, as an attenuation coefficient per
 * unit distance (transmittance exp(-opacity * length / unit distance));
 * SetOpacityConventionToSampled() reads it as the image-data mappers do, as the opacity
 * accumulated over one unit distance (transmittance (1 - opacity)^(length / unit)).
 *
 * Like the other ray cast mappers it renders an image ImageSampleDistance times smaller
 * than the viewport (adjusted automatically to the render window's desired update rate
 * when AutoAdjustSampleDistances is on) and shows it through vtkRayCastImageDisplayHelper.
 * It fires progress events and honours render window aborts between image bands.
 */

#ifndef vtkCylVolMapper_h
#define vtkCylVolMapper_h

#include "vtkCylVolRenderingModule.h" // for export macro
#include "vtkUnstructuredGridVolumeMapper.h"

class vtkRayCastImageDisplayHelper;
class vtkTimerLog;

class VTKCYLVOLRENDERING_EXPORT vtkCylVolMapper : public vtkUnstructuredGridVolumeMapper
{
public:
  static vtkCylVolMapper* New();
  vtkTypeMacro(vtkCylVolMapper, vtkUnstructuredGridVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Minimum-intensity projection (BlendMode 2, vtkVolumeMapper::MINIMUM_INTENSITY_BLEND).
  void SetBlendModeToMinimumIntensity() { this->SetBlendMode(2); }

  /// The acceleration structures (values of cylvol's CylvolStructure).
  enum StructureType
  {
    STRUCTURE_AUTO = 0,
    STRUCTURE_CARTESIAN_GRID = 1,
    STRUCTURE_CYLINDRICAL_GRID = 2,
    STRUCTURE_CARTESIAN_BVH = 3,
    STRUCTURE_CYLINDRICAL_BVH = 4
  };

  /// How scalar opacity values are read (see the class description).
  enum OpacityConventionType
  {
    OPACITY_ATTENUATION = 0,
    OPACITY_SAMPLED = 1
  };

  ///@{
  /**
   * The acceleration structure to build (default STRUCTURE_AUTO: cylvol picks one from the
   * mesh). Changing it rebuilds the structure at the next render.
   */
  virtual void SetStructure(int structure);
  vtkGetMacro(Structure, int);
  void SetStructureToAuto() { this->SetStructure(STRUCTURE_AUTO); }
  void SetStructureToCartesianGrid() { this->SetStructure(STRUCTURE_CARTESIAN_GRID); }
  void SetStructureToCylindricalGrid() { this->SetStructure(STRUCTURE_CYLINDRICAL_GRID); }
  void SetStructureToCartesianBVH() { this->SetStructure(STRUCTURE_CARTESIAN_BVH); }
  void SetStructureToCylindricalBVH() { this->SetStructure(STRUCTURE_CYLINDRICAL_BVH); }
  ///@}

  ///@{
  /**
   * The machine axis used by the cylindrical structures: detected from the mesh when
   * AxisAuto is on (the default), else AxisOrigin and AxisDirection (in data coordinates).
   * Changing these rebuilds the structure at the next render.
   */
  virtual void SetAxisAuto(vtkTypeBool value);
  vtkGetMacro(AxisAuto, vtkTypeBool);
  vtkBooleanMacro(AxisAuto, vtkTypeBool);
  virtual void SetAxisOrigin(double x, double y, double z);
  virtual void SetAxisOrigin(const double origin[3])
  {
    this->SetAxisOrigin(origin[0], origin[1], origin[2]);
  }
  vtkGetVector3Macro(AxisOrigin, double);
  virtual void SetAxisDirection(double x, double y, double z);
  virtual void SetAxisDirection(const double direction[3])
  {
    this->SetAxisDirection(direction[0], direction[1], direction[2]);
  }
  vtkGetVector3Macro(AxisDirection, double);
  ///@}

  ///@{
  /**
   * Structure build preset: 0 default, 1 fast build, 2 compact (grids) / fine (BVHs), 3 the
   * talk's grid sizes (grids; BVHs as 0), 4 fine grids (fewest cells tested, about ten times
   * the memory; BVHs as 2), as CylvolBuildParams::preset says. Changing it rebuilds the
   * structure at the next render.
   */
  virtual void SetBuildPreset(int preset);
  vtkGetMacro(BuildPreset, int);
  ///@}

  ///@{
  /**
   * Periodic copies: the input is one rotationally periodic sector of a machine (a blade
   * passage), and the whole wheel is drawn from it without copying the mesh. 0 (the default)
   * draws the input as it is; PERIODIC_AUTO (-1) finds whether the input is such a sector
   * about the machine axis and how many copies close the wheel (nothing is drawn, with an
   * error saying why, where it is not); N >= 1 draws N copies, each the sector turned by
   * 360/N degrees. A vector's component turns with its copy, as vtkAngularPeriodicFilter
   * turns vectors; scalars and magnitudes are the sector's. SetCopyRange(first, end) draws
   * copies first to end - 1 only (0, 0: all of them). GetBounds() gives the wheel's box.
   * Changing these rebuilds the structure at the next render.
   */
  enum
  {
    PERIODIC_AUTO = -1
  };
  virtual void SetPeriodicCopies(int copies);
  vtkGetMacro(PeriodicCopies, int);
  void SetPeriodicCopiesToAuto() { this->SetPeriodicCopies(PERIODIC_AUTO); }
  virtual void SetCopyRange(int first, int end);
  vtkGetVector2Macro(CopyRange, int);
  ///@}

  /**
   * The box of what is drawn: the input's, or with periodic copies the cylinder about the
   * machine axis that holds the copies drawn (the structure is built here if it is not yet).
   */
  double* GetBounds() override;
  void GetBounds(double bounds[6]) override { this->Superclass::GetBounds(bounds); }

  ///@{
  /**
   * Rays stop once their accumulated opacity reaches this value (default 0.99; 1 disables
   * early ray termination).
   */
  vtkSetClampMacro(EarlyTermination, double, 0.0, 1.0);
  vtkGetMacro(EarlyTermination, double);
  ///@}

  ///@{
  /**
   * Distance between samples along a ray, in data units. 0 or less (the default) uses
   * cylvol's default step for the mesh (half the mean cell size).
   */
  vtkSetMacro(SampleDistance, double);
  vtkGetMacro(SampleDistance, double);
  ///@}

  ///@{
  /**
   * When SampleDistance is 0 or less, the step is cylvol's default step times this factor
   * (default 1; 2 halves the samples, 0.125 is a converged reference).
   */
  vtkSetClampMacro(RelativeSampleDistance, double, 1e-3, 1e3);
  vtkGetMacro(RelativeSampleDistance, double);
  ///@}

  ///@{
  /**
   * The largest colour error allowed, in 1/255 of a pixel's premultiplied RGBA, against the
   * converged image (what the samples approach as they get denser); 0 (the default) samples
   * every sample distance. Above 0, compositing places its samples along each ray where the
   * field and the transfer function need them: the sample distance (SampleDistance, or
   * cylvol's default step times RelativeSampleDistance) is then the step each ray starts
   * with, and the steps adapt from 1/64 to 32 times it to hold the error, so the error wins
   * over the sample distance; rays stop early no sooner than their share of the error allows
   * (the stricter of that and EarlyTermination). 2 is measured at least as accurate as VTK's
   * ray caster. Intensity projections keep the fixed sample distance and ignore it. A
   * negative, NaN or infinite value is an error at the next render, and nothing is drawn.
   * GetLastRefinedSamples, GetLastSlopes and GetLastIntegratedStretches count the work of an
   * error-bounded render (all 0 at the fixed step).
   */
  vtkSetMacro(MaximumError, double);
  vtkGetMacro(MaximumError, double);
  ///@}

  ///@{
  /**
   * How many cells ahead, about, a ray still marches from cell to cell to its next sample
   * (default 6), times the cells a look-up through the structure tests on average (about 1
   * on a BVH of well-shaped cells, 7-19 on a grid): a sample further ahead, where the ray
   * provably stays in the mesh, is located
   * through the structure instead (GetLastFarLocates), which pays at sample distances of many
   * cells. The image is the same either way; VTK_DOUBLE_MAX always marches.
   */
  vtkSetClampMacro(MarchReach, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MarchReach, double);
  ///@}

  ///@{
  /**
   * Sample distance in screen pixels: the image is rendered this many times smaller than
   * the viewport in each direction and stretched over it (default 1).
   */
  vtkSetClampMacro(ImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(ImageSampleDistance, float);
  vtkSetClampMacro(MinimumImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(MinimumImageSampleDistance, float);
  vtkSetClampMacro(MaximumImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(MaximumImageSampleDistance, float);
  ///@}

  ///@{
  /**
   * When on, ImageSampleDistance is adjusted before each render from the previous render's
   * time and the time the renderer allocated to the volume (from the render window's
   * desired update rate), within [Minimum, Maximum]ImageSampleDistance. Default off.
   */
  vtkSetClampMacro(AutoAdjustSampleDistances, vtkTypeBool, 0, 1);
  vtkGetMacro(AutoAdjustSampleDistances, vtkTypeBool);
  vtkBooleanMacro(AutoAdjustSampleDistances, vtkTypeBool);
  ///@}

  /// ScalarComponent values that choose no single component.
  enum ScalarComponentChoice
  {
    SCALAR_COMPONENT_NONE = -1,
    SCALAR_MAGNITUDE = -2
  };

  ///@{
  /**
   * Which component of a multi-component scalar array to render (SCALAR_COMPONENT_NONE, -1,
   * the default: none chosen, which is an error for arrays with more than one component), or
   * SCALAR_MAGNITUDE for the vectors' magnitude (as a colour map's magnitude mode shows
   * them). It is drawn through the volume property's first transfer functions, as
   * vtkSmartVolumeMapper's component mode draws one; VTK's unstructured mappers would
   * instead mix every component, each through its own functions. Several components with the
   * property's IndependentComponents off (VTK reads them as colour and opacity) are an error,
   * and nothing is drawn. A one-component array is drawn as it is whatever this says.
   */
  virtual void SetScalarComponent(int component);
  vtkGetMacro(ScalarComponent, int);
  ///@}

  ///@{
  /**
   * Opacity convention (default OPACITY_ATTENUATION, as vtkUnstructuredGridVolumeRayCastMapper).
   */
  vtkSetClampMacro(OpacityConvention, int, OPACITY_ATTENUATION, OPACITY_SAMPLED);
  vtkGetMacro(OpacityConvention, int);
  void SetOpacityConventionToAttenuation() { this->SetOpacityConvention(OPACITY_ATTENUATION); }
  void SetOpacityConventionToSampled() { this->SetOpacityConvention(OPACITY_SAMPLED); }
  ///@}

  ///@{
  /**
   * Whether the depth of opaque geometry already drawn stops the rays (default on).
   */
  vtkSetClampMacro(IntermixIntersectingGeometry, vtkTypeBool, 0, 1);
  vtkGetMacro(IntermixIntersectingGeometry, vtkTypeBool);
  vtkBooleanMacro(IntermixIntersectingGeometry, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Statistics of the last render: wall time of Render() (seconds, build included when it
   * built), cylvol's own render time, rays, samples, samples located through the
   * structure, hexahedron containment tests, structure node visits, gradient evaluations
   * (zero unless shading or a gradient opacity asks for them), rays stopped early, the
   * image size, and the fast path's own work: samples skipped in transparent cells, those of
   * them placed by their cell's face planes alone (no inverse map), cells crossed by face
   * planes, jumps over transparent space, and an intensity projection's samples passed over
   * in cells that cannot beat the ray's extreme so far and its jumps over such cells.
   */
  vtkGetMacro(LastRenderSeconds, double);
  vtkGetMacro(LastRaySeconds, double);
  vtkGetMacro(LastRays, vtkTypeUInt64);
  vtkGetMacro(LastSamples, vtkTypeUInt64);
  vtkGetMacro(LastSamplesLocated, vtkTypeUInt64);
  vtkGetMacro(LastHexTests, vtkTypeUInt64);
  vtkGetMacro(LastInternalVisits, vtkTypeUInt64);
  vtkGetMacro(LastLeafVisits, vtkTypeUInt64);
  vtkGetMacro(LastGradientEvaluations, vtkTypeUInt64);
  vtkGetMacro(LastEarlyTerminations, vtkTypeUInt64);
  vtkGetVector2Macro(LastImageSize, int);
  vtkGetMacro(LastSamplesSkipped, vtkTypeUInt64);
  vtkGetMacro(LastPlaneCertified, vtkTypeUInt64);
  vtkGetMacro(LastWalkSteps, vtkTypeUInt64);
  vtkGetMacro(LastTransparentJumps, vtkTypeUInt64);
  vtkGetMacro(LastExtremeSkips, vtkTypeUInt64);
  vtkGetMacro(LastExtremeJumps, vtkTypeUInt64);
  vtkGetMacro(LastFarLocates, vtkTypeUInt64);
  ///@}

  ///@{
  /**
   * The work of the last error-bounded render (MaximumError above 0; all 0 at the fixed
   * step): samples added between two others where the stretch between them was too long for
   * the error allowed or crossed an active cell (also counted in GetLastSamples), slopes of
   * the scalar along the rays taken at the samples, and stretches of rays integrated
   * through the transfer function.
   */
  vtkGetMacro(LastRefinedSamples, vtkTypeUInt64);
  vtkGetMacro(LastSlopes, vtkTypeUInt64);
  vtkGetMacro(LastIntegratedStretches, vtkTypeUInt64);
  ///@}

  ///@{
  /**
   * Statistics of the structure: how many times it has been built by this mapper, how many
   * times only the scalars were replaced, the last build's time (seconds) and memory
   * (bytes), the structure built (a StructureType, never AUTO; -1 before the first build),
   * the axis it used, and the sample distance last used.
   */
  vtkGetMacro(BuildCount, int);
  vtkGetMacro(ScalarUpdateCount, int);
  vtkGetMacro(LastBuildSeconds, double);
  vtkGetMacro(LastBuildBytes, vtkTypeUInt64);
  vtkGetMacro(BuiltStructure, int);
  vtkGetVector3Macro(BuiltAxisOrigin, double);
  vtkGetVector3Macro(BuiltAxisDirection, double);
  vtkGetMacro(LastSampleDistance, double);
  ///@}

  ///@{
  /**
   * The periodic copies of the last build: how many close the wheel (0 where none are
   * drawn), the copies drawn (first, end), the sector's span in degrees, and the worst
   * mismatch of its sides (a fraction of the cell edge there).
   */
  vtkGetMacro(BuiltPeriodicCopies, int);
  vtkGetVector2Macro(BuiltCopyRange, int);
  vtkGetMacro(BuiltPeriodicSpan, double);
  vtkGetMacro(BuiltPeriodicMismatch, double);
  ///@}

  /**
   * How many cells of the given VTK cell type (VTK_HEXAHEDRON, VTK_TETRA, ...) the structure
   * was last built over: the cells handed to cylvol, as they were given (0 before any build).
   */
  vtkIdType GetBuiltCellCount(int cellType);

  /**
   * The cylvol library version string.
   */
  static const char* GetCylVolVersion();

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE.
   * Renders the volume.
   */
  void Render(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE.
   * Releases the display helper's graphics resources.
   */
  void ReleaseGraphicsResources(vtkWindow* win) override;

protected:
  vtkCylVolMapper();
  ~vtkCylVolMapper() override;

  // The input is marked optional so that a mapper without one reports it itself (an error
  // naming the problem, nothing drawn) instead of the pipeline failing the update.
  int FillInputPortInformation(int port, vtkInformation* info) override;

  int Structure;
  vtkTypeBool AxisAuto;
  double AxisOrigin[3];
  double AxisDirection[3];
  int BuildPreset;
  int PeriodicCopies;
  int CopyRange[2];
  double EarlyTermination;
  double SampleDistance;
  double RelativeSampleDistance;
  double MaximumError;
  double MarchReach;
  float ImageSampleDistance;
  float MinimumImageSampleDistance;
  float MaximumImageSampleDistance;
  vtkTypeBool AutoAdjustSampleDistances;
  int ScalarComponent;
  int OpacityConvention;
  vtkTypeBool IntermixIntersectingGeometry;

  double LastRenderSeconds;
  double LastRaySeconds;
  vtkTypeUInt64 LastRays;
  vtkTypeUInt64 LastSamples;
  vtkTypeUInt64 LastSamplesLocated;
  vtkTypeUInt64 LastHexTests;
  vtkTypeUInt64 LastInternalVisits;
  vtkTypeUInt64 LastLeafVisits;
  vtkTypeUInt64 LastGradientEvaluations;
  vtkTypeUInt64 LastEarlyTerminations;
  vtkTypeUInt64 LastSamplesSkipped;
  vtkTypeUInt64 LastPlaneCertified;
  vtkTypeUInt64 LastWalkSteps;
  vtkTypeUInt64 LastTransparentJumps;
  vtkTypeUInt64 LastExtremeSkips;
  vtkTypeUInt64 LastExtremeJumps;
  vtkTypeUInt64 LastFarLocates;
  vtkTypeUInt64 LastRefinedSamples;
  vtkTypeUInt64 LastSlopes;
  vtkTypeUInt64 LastIntegratedStretches;
  int LastImageSize[2];
  int BuildCount;
  int ScalarUpdateCount;
  double LastBuildSeconds;
  vtkTypeUInt64 LastBuildBytes;
  int BuiltStructure;
  double BuiltAxisOrigin[3];
  double BuiltAxisDirection[3];
  double LastSampleDistance;
  int BuiltPeriodicCopies;
  int BuiltCopyRange[2];
  double BuiltPeriodicSpan;
  double BuiltPeriodicMismatch;

  vtkRayCastImageDisplayHelper* ImageDisplayHelper;
  vtkTimerLog* Timer;

  class vtkInternals;
  vtkInternals* Internals;

private:
  // The steps of Render, in order. Each returns false (after vtkErrorMacro) when the frame
  // is to draw nothing; Frame carries what one step hands to the next.
  struct Frame;
  void ResetRenderStatistics();
  bool SelectInput(Frame& frame);        // the input, without its ghost cells
  bool SelectScalars(Frame& frame);      // the scalar array and component drawn
  bool CheckCellTypes(Frame& frame);
  bool UpdateVolume(Frame& frame);       // build, or hand over new scalars, or keep
  bool PrepareVolume(Frame& frame);      // the input, scalars and cell types, then UpdateVolume
  bool BuildVolume(Frame& frame);
  void RecordBuildStatistics();
  bool ReplaceScalars(Frame& frame);
  bool MakeTransferTables(Frame& frame); // colour, opacity and gradient opacity tables
  void SizeImage(Frame& frame, vtkRenderer* ren, vtkVolume* vol);
  void ReadDepth(Frame& frame, vtkRenderer* ren); // the z-buffer of what is drawn
  void SetCamera(Frame& frame, vtkRenderer* ren, vtkVolume* vol);
  void SetRenderParameters(Frame& frame, vtkVolume* vol);
  bool RenderBands(Frame& frame, vtkRenderer* ren); // the cylvol_render calls
  void AddRenderStatistics();
  void Display(Frame& frame, vtkRenderer* ren, vtkVolume* vol);

  vtkCylVolMapper(const vtkCylVolMapper&) = delete;
  void operator=(const vtkCylVolMapper&) = delete;
};

#endif
