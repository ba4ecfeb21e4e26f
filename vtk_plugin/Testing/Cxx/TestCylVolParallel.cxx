// Baseline: the LOX post with a parallel camera, a gray transfer function, nearest
// interpolation and an image sample distance of 2 (the image is rendered at half size).
#include "vtkCylVolMapper.h"

#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkRegressionTestImage.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

int TestCylVolParallel(int argc, char* argv[])
{
  cylvoltest::Dataset d = cylvoltest::Load("post");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkCylVolMapper> mapper;
  mapper->SetInputData(d.Grid);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectScalarArray(d.Scalar.c_str());
  mapper->SetImageSampleDistance(2.0f);
  auto property = cylvoltest::MakeProperty(d, false);
  vtkNew<vtkPiecewiseFunction> gray;
  gray->AddPoint(d.Range[0], 0.2);
  gray->AddPoint(d.Range[1], 1.0);
  property->SetColor(gray);
  property->SetInterpolationTypeToNearest();

  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  auto win = cylvoltest::MakeWindow(300, 300, ren);
  ren->GetActiveCamera()->ParallelProjectionOn();
  cylvoltest::SetCamera(ren, 40.0, 30.0, 1.5);
  win->Render();
  if (mapper->GetLastImageSize()[0] != 150 || mapper->GetLastImageSize()[1] != 150)
  {
    std::cerr << "ImageSampleDistance 2 rendered " << mapper->GetLastImageSize()[0] << "x"
              << mapper->GetLastImageSize()[1] << " instead of 150x150\n";
    return EXIT_FAILURE;
  }
  const int result = vtkRegressionTestImageThreshold(win, 0.05);
  return result == vtkRegressionTester::FAILED ? EXIT_FAILURE : EXIT_SUCCESS;
}
