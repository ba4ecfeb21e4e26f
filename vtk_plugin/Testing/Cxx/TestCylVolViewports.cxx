// Baseline: the OpenFOAM mixer in four viewports of one window, from four directions, the
// left column unshaded and the right column shaded (ambient/diffuse/specular), perspective.
#include "vtkCylVolMapper.h"

#include "vtkNew.h"
#include "vtkRegressionTestImage.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

int TestCylVolViewports(int argc, char* argv[])
{
  cylvoltest::Dataset d = cylvoltest::Load("mixer");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkCylVolMapper> mapper;
  mapper->SetInputData(d.Grid);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectScalarArray("p");
  auto flat = cylvoltest::MakeProperty(d, false);
  auto shaded = cylvoltest::MakeProperty(d, true);

  vtkNew<vtkRenderWindow> win;
  win->SetOffScreenRendering(1);
  win->SetMultiSamples(0);
  win->SetSize(300, 300);
  const double views[4][3] = { { 30, 20, 1.3 }, { 30, 20, 1.3 }, { -60, 50, 1.2 }, { 160, -30, 1.4 } };
  for (int k = 0; k < 4; ++k)
  {
    vtkNew<vtkVolume> volume;
    volume->SetMapper(mapper);
    volume->SetProperty(k % 2 ? shaded : flat);
    vtkNew<vtkRenderer> ren;
    ren->SetViewport(0.5 * (k % 2), 0.5 * (k / 2), 0.5 * (k % 2) + 0.5, 0.5 * (k / 2) + 0.5);
    ren->SetBackground(0.1, 0.1, 0.15);
    ren->AddVolume(volume);
    win->AddRenderer(ren);
    cylvoltest::SetCamera(ren, views[k][0], views[k][1], views[k][2]);
  }
  win->Render();
  if (mapper->GetBuildCount() != 1)
  {
    std::cerr << "four viewports built the structure " << mapper->GetBuildCount() << " times\n";
    return EXIT_FAILURE;
  }
  const int result = vtkRegressionTestImageThreshold(win, 0.05);
  return result == vtkRegressionTester::FAILED ? EXIT_FAILURE : EXIT_SUCCESS;
}
