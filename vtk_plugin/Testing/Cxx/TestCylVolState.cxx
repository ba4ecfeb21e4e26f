// The mapper's state across frames, on the hexa cube:
// - the structure is built once and kept while the camera moves (BuildCount stays 1);
// - new scalar values, or another array, are handed over without a rebuild
//   (ScalarUpdateCount grows, BuildCount does not) and change the image;
// - structure settings and moved points rebuild;
// - progress events run from 0 to 1; an abort requested by the render window stops the
//   frame and nothing is drawn;
// - AutoAdjustSampleDistances raises ImageSampleDistance for a demanding update rate;
// - the statistics of the last render are filled in.
#include "vtkCylVolMapper.h"

#include "vtkCallbackCommand.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

namespace
{
int failures = 0;
void Expect(bool condition, const std::string& what)
{
  std::cout << (condition ? "ok   " : "FAIL ") << what << "\n";
  failures += condition ? 0 : 1;
}

double lastProgress = -1.0;
int progressEvents = 0;
void OnProgress(vtkObject*, unsigned long, void*, void* callData)
{
  lastProgress = *static_cast<double*>(callData);
  progressEvents++;
}

// Asks the render window to abort as soon as the mapper reports its first progress.
vtkRenderWindow* abortWindow = nullptr;
void OnProgressAbort(vtkObject*, unsigned long, void*, void*)
{
  if (abortWindow)
  {
    abortWindow->SetAbortRender(1);
  }
}
} // namespace

int TestCylVolState(int, char*[])
{
  cylvoltest::Dataset d = cylvoltest::Load("hexa");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkCylVolMapper> mapper;
  mapper->SetInputData(d.Grid);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(cylvoltest::MakeProperty(d, false));
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  auto win = cylvoltest::MakeWindow(160, 160, ren);
  cylvoltest::SetCamera(ren, 30, 20, 1.2);

  vtkNew<vtkCallbackCommand> progress;
  progress->SetCallback(OnProgress);
  mapper->AddObserver(vtkCommand::ProgressEvent, progress);

  win->Render();
  auto first = cylvoltest::Grab(win);
  Expect(mapper->GetBuildCount() == 1, "first frame builds once");
  Expect(progressEvents >= 2 && lastProgress == 1.0, "progress events reach 1.0");
  Expect(mapper->GetLastSamples() > 0 && mapper->GetLastRays() > 0, "samples and rays counted");
  Expect(mapper->GetLastRenderSeconds() > 0.0, "render time measured");
  Expect(mapper->GetBuiltStructure() >= 1 && mapper->GetBuiltStructure() <= 4, "a concrete structure was built");
  Expect(mapper->GetLastImageSize()[0] == 160 && mapper->GetLastImageSize()[1] == 160, "image 160x160");
  Expect(cylvoltest::Lit(first) > 1000, "the first frame shows the volume");
  Expect(mapper->GetLastGradientEvaluations() == 0, "no gradients without shading or gradient opacity");
  Expect(mapper->GetLastWalkSteps() > 0, "the fast path crosses cells by face planes");
  const vtkTypeUInt64 skippedFirst = mapper->GetLastSamplesSkipped();

  // Transparent cells: the lower half of the range is skipped, partly by face planes alone.
  {
    vtkNew<vtkPiecewiseFunction> upper;
    upper->AddPoint(d.Range[0], 0.0);
    upper->AddPoint(0.5 * (d.Range[0] + d.Range[1]), 0.0);
    upper->AddPoint(d.Range[1], 1.0);
    vtkPiecewiseFunction* kept = volume->GetProperty()->GetScalarOpacity();
    kept->Register(nullptr);
    volume->GetProperty()->SetScalarOpacity(upper);
    win->Render();
    const vtkTypeUInt64 skipped = mapper->GetLastSamplesSkipped();
    Expect(skipped > skippedFirst && skipped <= mapper->GetLastSamplesLocated(),
      "samples in the cells made transparent are skipped");
    Expect(mapper->GetLastPlaneCertified() <= skipped, "face planes place only skipped samples");
    if (mapper->GetBuiltStructure() >= vtkCylVolMapper::STRUCTURE_CARTESIAN_BVH)
    {
      Expect(mapper->GetLastTransparentJumps() > 0, "a BVH jumps over transparent space");
    }
    volume->GetProperty()->SetScalarOpacity(kept);
    kept->UnRegister(nullptr);
  }

  // A sample distance of many cells: samples far ahead are located through the structure
  // rather than by crossing every cell on the way.
  {
    mapper->SetRelativeSampleDistance(16.0);
    win->Render();
    Expect(mapper->GetLastFarLocates() > 0 &&
        mapper->GetLastFarLocates() <= mapper->GetLastSamplesLocated(),
      "samples many cells apart are located through the structure");
    auto far = cylvoltest::Grab(win);
    Expect(cylvoltest::Lit(far) > 1000, "and still show the volume");
    const double reach = mapper->GetMarchReach();
    Expect(reach == 6.0, "the march reach is cylvol's default");
    mapper->SetMarchReach(VTK_DOUBLE_MAX);
    win->Render();
    Expect(mapper->GetLastFarLocates() == 0, "a march reach without end always marches");
    Expect(cylvoltest::Compare(far, cylvoltest::Grab(win), 1).Within > 0.999,
      "to the same picture");
    mapper->SetMarchReach(reach);
    mapper->SetRelativeSampleDistance(1.0);
  }

  // Gradient opacity: only when enabled and not the default constant 1.
  vtkVolumeProperty* property = volume->GetProperty();
  vtkNew<vtkPiecewiseFunction> one;
  one->AddPoint(0.0, 1.0);
  one->AddPoint(10.0, 1.0);
  property->SetGradientOpacity(one);
  win->Render();
  Expect(mapper->GetLastGradientEvaluations() == 0, "a constant-1 gradient opacity computes no gradients");
  vtkNew<vtkPiecewiseFunction> ramp;
  ramp->AddPoint(0.0, 0.0);
  ramp->AddPoint(2.0 * (d.Range[1] - d.Range[0]), 1.0);
  property->SetGradientOpacity(ramp);
  win->Render();
  auto gradient = cylvoltest::Grab(win);
  Expect(mapper->GetLastGradientEvaluations() > 0, "a gradient opacity ramp evaluates gradients");
  Expect(cylvoltest::Compare(first, gradient, 8).Within < 0.9, "and changes the image");
  property->DisableGradientOpacityOn();
  win->Render();
  Expect(mapper->GetLastGradientEvaluations() == 0, "a disabled gradient opacity computes none");
  property->DisableGradientOpacityOff();
  property->SetGradientOpacity(one);
  property->ShadeOn();
  win->Render();
  Expect(mapper->GetLastGradientEvaluations() > 0, "shading evaluates gradients");
  property->ShadeOff();
  win->Render();
  Expect(cylvoltest::Compare(first, cylvoltest::Grab(win), 0).Within == 1.0, "back to the first image");

  for (int k = 0; k < 3; ++k)
  {
    ren->GetActiveCamera()->Azimuth(15.0);
    win->Render();
  }
  Expect(mapper->GetBuildCount() == 1, "moving the camera does not rebuild");
  Expect(mapper->GetScalarUpdateCount() == 0, "nor replace scalars");

  // New values in the same array.
  vtkDataArray* s = d.Grid->GetPointData()->GetScalars();
  for (vtkIdType i = 0; i < s->GetNumberOfTuples(); ++i)
  {
    s->SetComponent(i, 0, d.Range[0] + d.Range[1] - s->GetComponent(i, 0));
  }
  s->Modified();
  ren->GetActiveCamera()->Azimuth(-45.0);
  win->Render();
  auto flipped = cylvoltest::Grab(win);
  Expect(mapper->GetBuildCount() == 1, "new scalar values do not rebuild");
  Expect(mapper->GetScalarUpdateCount() == 1, "new scalar values are handed over");
  Expect(cylvoltest::Compare(first, flipped, 8).Within < 0.9, "and change the image");

  // Another array.
  vtkNew<vtkFloatArray> other;
  other->SetName("other");
  other->SetNumberOfTuples(d.Grid->GetNumberOfPoints());
  for (vtkIdType i = 0; i < other->GetNumberOfTuples(); ++i)
  {
    double p[3];
    d.Grid->GetPoint(i, p);
    other->SetValue(i, static_cast<float>(p[0] + p[1]));
  }
  d.Grid->GetPointData()->AddArray(other);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectScalarArray("other");
  win->Render();
  Expect(mapper->GetBuildCount() == 1, "another array does not rebuild");
  Expect(mapper->GetScalarUpdateCount() == 2, "another array is handed over");

  // Structure settings rebuild.
  mapper->SetStructureToCartesianBVH();
  win->Render();
  Expect(mapper->GetBuildCount() == 2, "a new structure setting rebuilds");
  Expect(mapper->GetBuiltStructure() == vtkCylVolMapper::STRUCTURE_CARTESIAN_BVH, "as a Cartesian BVH");
  mapper->SetStructureToCylindricalGrid();
  mapper->AxisAutoOff();
  mapper->SetAxisOrigin(0.5, 0.5, 0.5);
  mapper->SetAxisDirection(0.0, 0.0, 1.0);
  win->Render();
  Expect(mapper->GetBuildCount() == 3, "a given axis rebuilds");
  Expect(mapper->GetBuiltStructure() == vtkCylVolMapper::STRUCTURE_CYLINDRICAL_GRID, "as a cylindrical grid");
  win->Render();
  Expect(mapper->GetBuildCount() == 3, "and is kept");

  // Moved points rebuild.
  double p[3];
  d.Grid->GetPoints()->GetPoint(0, p);
  d.Grid->GetPoints()->SetPoint(0, p[0] - 0.01, p[1], p[2]);
  d.Grid->GetPoints()->Modified();
  win->Render();
  Expect(mapper->GetBuildCount() == 4, "moved points rebuild");

  // Image sample distance.
  mapper->SetImageSampleDistance(2.0f);
  win->Render();
  Expect(mapper->GetLastImageSize()[0] == 80 && mapper->GetLastImageSize()[1] == 80, "ImageSampleDistance 2 renders 80x80");
  mapper->SetImageSampleDistance(1.0f);

  // Automatic sample distance for a demanding update rate.
  mapper->AutoAdjustSampleDistancesOn();
  mapper->SetMaximumImageSampleDistance(4.0f);
  win->SetDesiredUpdateRate(5000.0);
  for (int k = 0; k < 4; ++k)
  {
    win->Render();
  }
  Expect(mapper->GetImageSampleDistance() > 1.0f, "AutoAdjustSampleDistances raised ImageSampleDistance to " +
      std::to_string(mapper->GetImageSampleDistance()));
  Expect(mapper->GetImageSampleDistance() <= 4.0f, "within the maximum");
  mapper->AutoAdjustSampleDistancesOff();
  mapper->SetImageSampleDistance(1.0f);
  win->SetDesiredUpdateRate(0.0001);

  // Abort: once the mapper has started (its first progress event), the window is asked to
  // abort; the mapper sees it at its next check, casts no more rays and draws nothing.
  vtkNew<vtkCallbackCommand> abort;
  abort->SetCallback(OnProgressAbort);
  mapper->AddObserver(vtkCommand::ProgressEvent, abort);
  abortWindow = win;
  win->Render();
  abortWindow = nullptr;
  mapper->RemoveObserver(abort);
  win->SetAbortRender(0);
  Expect(mapper->GetLastRays() == 0, "an aborted frame casts no rays");
  win->Render();
  Expect(mapper->GetLastRays() > 0, "the next frame renders again");

  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
