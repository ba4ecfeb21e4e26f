// The mapper's blend modes on a case with a known answer: a unit slab of 4x4x4 hexahedra whose
// scalar is s = x + z / 2, seen from above with a parallel camera. Along every ray s runs from
// x (bottom) to x + 1/2 (top), so a maximum-intensity projection must show, at each pixel, the
// colour of s = x + 1/2 with the opacity of one unit distance there (attenuation convention:
// 1 - exp(-opacity)), over black; a minimum-intensity projection the same for s = x. Both are
// checked within 3/255 on every pixel; compositing must differ from both. Then a blend mode the
// mapper does not know (3, average intensity) is reported and draws nothing, and on a fresh
// mapper builds nothing either.
#include "vtkCylVolMapper.h"

#include "vtkCommand.h"
#include "vtkDoubleArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkTestErrorObserver.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

namespace
{
const int kSize = 80;
const double kScale = 0.4; // parallel scale: the view spans [0.1, 0.9] in x and y

vtkSmartPointer<vtkUnstructuredGrid> Slab()
{
  return cylvoltest::UnitSlab(4, [](double x, double, double z) { return x + 0.5 * z; });
}

struct Scene
{
  vtkNew<vtkCylVolMapper> Mapper;
  vtkNew<vtkVolumeProperty> Property;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Ren;
  vtkSmartPointer<vtkRenderWindow> Win;
  vtkNew<vtkTest::ErrorObserver> Errors;

  Scene()
  {
    vtkNew<vtkColorTransferFunction> color;
    color->AddRGBPoint(0.0, 0.0, 0.2, 1.0);
    color->AddRGBPoint(1.5, 1.0, 0.6, 0.0);
    vtkNew<vtkPiecewiseFunction> opacity;
    opacity->AddPoint(0.0, 0.2);
    opacity->AddPoint(1.5, 2.0);
    this->Property->SetColor(color);
    this->Property->SetScalarOpacity(opacity);
    this->Property->SetScalarOpacityUnitDistance(0.5);
    this->Property->SetInterpolationTypeToLinear();
    this->Property->ShadeOn(); // a projection shades nothing
    this->Mapper->SetInputData(Slab());
    this->Mapper->SetSampleDistance(0.002);
    this->Mapper->AddObserver(vtkCommand::ErrorEvent, this->Errors);
    this->Volume->SetMapper(this->Mapper);
    this->Volume->SetProperty(this->Property);
    this->Ren->AddVolume(this->Volume);
    this->Win = cylvoltest::MakeWindow(kSize, kSize, this->Ren);
    vtkCamera* cam = this->Ren->GetActiveCamera();
    cam->ParallelProjectionOn();
    cam->SetParallelScale(kScale);
    cam->SetFocalPoint(0.5, 0.5, 0.5);
    cam->SetPosition(0.5, 0.5, 3.0);
    cam->SetViewUp(0.0, 1.0, 0.0);
    this->Ren->ResetCameraClippingRange();
  }

  vtkSmartPointer<vtkImageData> Render(int blend)
  {
    this->Errors->Clear();
    this->Mapper->SetBlendMode(blend);
    this->Win->Render();
    return cylvoltest::Grab(this->Win);
  }

  // The pixel (0..255 per channel) the projection of the extreme `s` must give.
  void Expected(double s, double out[3])
  {
    double c[3];
    this->Property->GetRGBTransferFunction()->GetColor(s, c);
    const double alpha = 1.0 - std::exp(-this->Property->GetScalarOpacity()->GetValue(s));
    for (int k = 0; k < 3; ++k)
    {
      out[k] = 255.0 * c[k] * alpha;
    }
  }

  // The largest channel error of `image` against the projection of x + `offset` per pixel.
  double Error(vtkImageData* image, double offset)
  {
    const unsigned char* p =
      static_cast<unsigned char*>(image->GetPointData()->GetScalars()->GetVoidPointer(0));
    double worst = 0.0;
    for (int j = 0; j < kSize; ++j)
    {
      for (int i = 0; i < kSize; ++i)
      {
        const double x = 0.5 + kScale * (2.0 * (i + 0.5) / kSize - 1.0);
        double want[3];
        this->Expected(x + offset, want);
        for (int k = 0; k < 3; ++k)
        {
          worst = std::max(worst, std::abs(p[3 * (j * kSize + i) + k] - want[k]));
        }
      }
    }
    return worst;
  }
};
} // namespace

int TestCylVolBlend(int, char*[])
{
  Scene scene;
  bool ok = true;

  auto maximum = scene.Render(vtkUnstructuredGridVolumeMapper::MAXIMUM_INTENSITY_BLEND);
  const double maxTop = scene.Error(maximum, 0.5), maxBottom = scene.Error(maximum, 0.0);
  scene.Mapper->SetBlendModeToMinimumIntensity();
  auto minimum = scene.Render(scene.Mapper->GetBlendMode());
  const double minBottom = scene.Error(minimum, 0.0), minTop = scene.Error(minimum, 0.5);
  auto composite = scene.Render(vtkUnstructuredGridVolumeMapper::COMPOSITE_BLEND);
  const double compTop = scene.Error(composite, 0.5), compBottom = scene.Error(composite, 0.0);
  std::cout << "maximum: " << maxTop << "/255 from the top's projection (" << maxBottom
            << " from the bottom's)\nminimum: " << minBottom << "/255 from the bottom's ("
            << minTop << " from the top's)\ncomposite: " << compTop << ", " << compBottom
            << "\n";
  ok &= maxTop <= 3.0 && minBottom <= 3.0;
  ok &= maxBottom > 20.0 && minTop > 20.0 && compTop > 20.0 && compBottom > 20.0;
  ok &= !scene.Errors->GetError();

  scene.Render(vtkUnstructuredGridVolumeMapper::MAXIMUM_INTENSITY_BLEND);
  std::cout << "maximum with shading on: " << scene.Mapper->GetLastGradientEvaluations()
            << " gradients; " << scene.Mapper->GetLastExtremeSkips() << " of "
            << scene.Mapper->GetLastSamplesLocated() << " located samples passed over, "
            << scene.Mapper->GetLastExtremeJumps() << " jumps over "
            << scene.Mapper->GetLastSamples() << " samples\n";
  ok &= scene.Mapper->GetLastGradientEvaluations() == 0;
  // The maximum comes first on every ray (s grows with z): the cells below it cannot beat it,
  // and each ray jumps past them (the default structure is a BVH), locating few samples.
  ok &= scene.Mapper->GetLastExtremeSkips() > 0 && scene.Mapper->GetLastExtremeJumps() > 0;
  ok &= 2 * scene.Mapper->GetLastSamplesLocated() < scene.Mapper->GetLastSamples();

  auto unknown = scene.Render(3);
  const bool reported = scene.Errors->GetError() &&
    std::string(scene.Errors->GetErrorMessage()).find("Unsupported blend mode 3") != std::string::npos;
  const unsigned char* p =
    static_cast<unsigned char*>(unknown->GetPointData()->GetScalars()->GetVoidPointer(0));
  vtkIdType lit = 0;
  for (vtkIdType i = 0; i < 3 * unknown->GetNumberOfPoints(); ++i)
  {
    lit += p[i] ? 1 : 0;
  }
  std::cout << "blend mode 3: " << (reported ? "reported" : "NOT reported") << ", " << lit
            << " lit channel values\n";
  ok &= reported && lit == 0;

  // Refused before anything is built: a fresh mapper asked for mode 3 builds no structure.
  Scene fresh;
  fresh.Render(3);
  const bool freshReported = fresh.Errors->GetError();
  std::cout << "blend mode 3 on a fresh mapper: " << (freshReported ? "reported" : "NOT reported")
            << ", " << fresh.Mapper->GetBuildCount() << " builds\n";
  ok &= freshReported && fresh.Mapper->GetBuildCount() == 0;
  fresh.Render(vtkUnstructuredGridVolumeMapper::MAXIMUM_INTENSITY_BLEND);
  ok &= !fresh.Errors->GetError() && fresh.Mapper->GetBuildCount() == 1;

  std::cout << (ok ? "passed" : "FAILED") << "\n";
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
