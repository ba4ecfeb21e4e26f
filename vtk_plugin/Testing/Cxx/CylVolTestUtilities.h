// Shared helpers of the vtkCylVolMapper tests: loading the test meshes, a transfer function
// and a camera that both mappers share, reading a window back, and comparing two images.
#ifndef CylVolTestUtilities_h
#define CylVolTestUtilities_h

#include "vtkAppendFilter.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataSetReader.h"
#include "vtkImageData.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkMultiBlockPLOT3DReader.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtkUnstructuredGridReader.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"
#include "vtkXMLUnstructuredGridReader.h"
#include "vtkNew.h"

#include <cstdio>
#include <vector>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#ifndef CYLVOL_DATA_DIR
#error "CYLVOL_DATA_DIR must name the shared data folder"
#endif
#ifndef CYLVOL_TEST_OUTPUT_DIR
#error "CYLVOL_TEST_OUTPUT_DIR must name a folder the tests may write to"
#endif

namespace cylvoltest
{

/// A test mesh: the grid and the point scalar array the data README suggests.
struct Dataset
{
  vtkSmartPointer<vtkUnstructuredGrid> Grid;
  std::string Scalar;
  bool Cells = false; // the scalar is cell data
  double Range[2] = { 0.0, 1.0 };
  double Diagonal = 1.0;
};

inline std::string DataPath(const std::string& file)
{
  return std::string(CYLVOL_DATA_DIR) + "/" + file;
}

inline std::string OutputPath(const std::string& file)
{
  return std::string(CYLVOL_TEST_OUTPUT_DIR) + "/" + file;
}

inline bool FileExists(const std::string& path)
{
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f)
  {
    std::fclose(f);
    return true;
  }
  return false;
}

inline vtkSmartPointer<vtkUnstructuredGrid> ReadPlot3D(const std::string& xyz, const std::string& q)
{
  vtkNew<vtkMultiBlockPLOT3DReader> reader;
  reader->SetFileName(DataPath(xyz).c_str());
  reader->SetQFileName(DataPath(q).c_str());
  reader->AutoDetectFormatOn();
  reader->Update();
  vtkDataSet* block = vtkDataSet::SafeDownCast(reader->GetOutput()->GetBlock(0));
  if (!block)
  {
    return nullptr;
  }
  vtkNew<vtkAppendFilter> append;
  append->AddInputData(block);
  append->Update();
  vtkSmartPointer<vtkUnstructuredGrid> grid = append->GetOutput();
  return grid;
}

/// Loads "hexa", "mixer", "comb", "post" from the shared data folder, or "pump" from the
/// file the CTest fixture generated (cylvol gen pump-rotor:20000); "mixer-cells" is the mixer
/// with its cell array p. Empty Grid on failure.
inline Dataset Load(const std::string& name)
{
  Dataset d;
  if (name == "hexa" || name == "mixer" || name == "mixer-cells")
  {
    vtkNew<vtkUnstructuredGridReader> reader;
    reader->SetFileName(DataPath(name == "hexa" ? "hexa.vtk" : "mixer.vtk").c_str());
    reader->ReadAllScalarsOn();
    reader->ReadAllVectorsOn();
    reader->ReadAllFieldsOn();
    reader->Update();
    d.Grid = reader->GetOutput();
    d.Scalar = name == "hexa" ? "scalars" : "p";
    d.Cells = name == "mixer-cells";
  }
  else if (name == "comb")
  {
    d.Grid = ReadPlot3D("combxyz.bin", "combq.bin");
    d.Scalar = "Density"; // the energy is all zeros
  }
  else if (name == "post")
  {
    d.Grid = ReadPlot3D("postxyz.bin", "postq.bin");
    d.Scalar = "StagnationEnergy"; // the density is constant
  }
  else if (name == "pump")
  {
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(OutputPath("pump-rotor-20k.vtu").c_str());
    reader->Update();
    d.Grid = reader->GetOutput();
    d.Scalar = "pressure";
  }
  if (!d.Grid || d.Grid->GetNumberOfCells() == 0)
  {
    std::cerr << "could not load dataset " << name << "\n";
    d.Grid = nullptr;
    return d;
  }
  vtkDataSetAttributes* attributes =
    d.Cells ? static_cast<vtkDataSetAttributes*>(d.Grid->GetCellData()) : d.Grid->GetPointData();
  vtkDataArray* a = attributes->GetArray(d.Scalar.c_str());
  if (!a)
  {
    std::cerr << "dataset " << name << " has no array " << d.Scalar << "\n";
    d.Grid = nullptr;
    return d;
  }
  attributes->SetActiveScalars(d.Scalar.c_str());
  a->GetRange(d.Range, 0);
  d.Diagonal = d.Grid->GetLength();
  return d;
}

/// The unit cube cut into n x n x n hexahedra, with the point scalar "s" = scalar(x, y, z):
/// the meshes with known answers of the slab and blend tests.
template <typename Scalar>
vtkSmartPointer<vtkUnstructuredGrid> UnitSlab(int n, Scalar scalar)
{
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  vtkNew<vtkDoubleArray> s;
  s->SetName("s");
  for (int k = 0; k <= n; ++k)
  {
    for (int j = 0; j <= n; ++j)
    {
      for (int i = 0; i <= n; ++i)
      {
        const double x = double(i) / n, y = double(j) / n, z = double(k) / n;
        points->InsertNextPoint(x, y, z);
        s->InsertNextValue(scalar(x, y, z));
      }
    }
  }
  grid->SetPoints(points);
  grid->GetPointData()->SetScalars(s);
  auto id = [n](int i, int j, int k) { return static_cast<vtkIdType>(i + (n + 1) * (j + (n + 1) * k)); };
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        vtkIdType c[8] = { id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1) };
        grid->InsertNextCell(VTK_HEXAHEDRON, 8, c);
      }
    }
  }
  return grid;
}

/// A colour ramp (blue, cyan, yellow, red) and an opacity ramp (0, 0.1, 0.5, 1) on the same
/// four abscissae over the scalar range; the unit distance is a tenth of the mesh diagonal, so
/// that the volume is neither clear nor opaque.
///
/// The opacity function has no control point of its own on purpose: VTK 9.1's unstructured ray
/// integrators (vtkUnstructuredGridLinearRayIntegrator and the pre-integration built on it)
/// collect only the FIRST control point of the opacity function (their loop stops at the
/// function's lower range instead of its upper one) and so interpolate opacity linearly
/// between the colour function's points. With an opacity point of its own (say 0 up to 15 %
/// of the range) VTK's image is measurably wrong: see TestCylVolSlab, where the exact answer
/// is known.
inline vtkSmartPointer<vtkVolumeProperty> MakeProperty(const Dataset& d, bool shade = false)
{
  const double lo = d.Range[0], hi = d.Range[1], w = hi - lo;
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(lo, 0.1, 0.2, 0.9);
  color->AddRGBPoint(lo + 0.35 * w, 0.1, 0.8, 0.8);
  color->AddRGBPoint(lo + 0.7 * w, 0.95, 0.85, 0.2);
  color->AddRGBPoint(hi, 0.9, 0.1, 0.1);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(lo, 0.0);
  opacity->AddPoint(lo + 0.35 * w, 0.1);
  opacity->AddPoint(lo + 0.7 * w, 0.5);
  opacity->AddPoint(hi, 1.0);
  auto property = vtkSmartPointer<vtkVolumeProperty>::New();
  property->SetColor(color);
  property->SetScalarOpacity(opacity);
  property->SetScalarOpacityUnitDistance(0.1 * d.Diagonal);
  property->SetInterpolationTypeToLinear();
  property->SetShade(shade ? 1 : 0);
  property->SetAmbient(0.3);
  property->SetDiffuse(0.7);
  property->SetSpecular(0.3);
  property->SetSpecularPower(20.0);
  return property;
}

/// Frames the grid's bounds, then turns the camera.
inline void SetCamera(vtkRenderer* ren, double azimuth, double elevation, double zoom)
{
  ren->ResetCamera();
  vtkCamera* cam = ren->GetActiveCamera();
  cam->Azimuth(azimuth);
  cam->Elevation(elevation);
  cam->OrthogonalizeViewUp();
  cam->Zoom(zoom);
  ren->ResetCameraClippingRange();
}

/// An off-screen render window of the given size with one black renderer.
inline vtkSmartPointer<vtkRenderWindow> MakeWindow(int w, int h, vtkRenderer* ren)
{
  auto win = vtkSmartPointer<vtkRenderWindow>::New();
  win->SetOffScreenRendering(1);
  win->SetMultiSamples(0);
  win->SetSize(w, h);
  ren->SetBackground(0.0, 0.0, 0.0);
  win->AddRenderer(ren);
  return win;
}

/// The window's colour buffer as an RGB image.
inline vtkSmartPointer<vtkImageData> Grab(vtkRenderWindow* win)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(win);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff();
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(grab->GetOutput());
  return image;
}

/// How many pixels of an RGB image are not black: the pixels a volume on a black
/// background lit.
inline vtkIdType Lit(vtkImageData* image)
{
  const unsigned char* p =
    static_cast<unsigned char*>(image->GetPointData()->GetScalars()->GetVoidPointer(0));
  vtkIdType lit = 0;
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    lit += (p[3 * i] | p[3 * i + 1] | p[3 * i + 2]) ? 1 : 0;
  }
  return lit;
}

inline void WritePNG(vtkImageData* image, const std::string& path)
{
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  writer->Write();
}

/// Per-pixel largest channel difference (0..255) of two RGB images of the same size.
inline int PixelDifference(vtkImageData* a, vtkImageData* b, vtkIdType pixel)
{
  const unsigned char* pa =
    static_cast<unsigned char*>(a->GetPointData()->GetScalars()->GetVoidPointer(0)) + 3 * pixel;
  const unsigned char* pb =
    static_cast<unsigned char*>(b->GetPointData()->GetScalars()->GetVoidPointer(0)) + 3 * pixel;
  int m = 0;
  for (int c = 0; c < 3; ++c)
  {
    m = std::max(m, std::abs(int(pa[c]) - int(pb[c])));
  }
  return m;
}

/// Image agreement: mean absolute difference per channel (in 1/255 units) and the fraction
/// of pixels whose channels all lie within `tolerance` / 255, over the pixels `mask` keeps
/// (all when mask is null).
struct Agreement
{
  double Mean = 0.0;
  double Within = 1.0;
  vtkIdType Pixels = 0;
};

inline Agreement Compare(vtkImageData* a, vtkImageData* b, int tolerance, const std::vector<char>* mask = nullptr)
{
  Agreement r;
  const vtkIdType n = a->GetNumberOfPoints();
  const unsigned char* pa = static_cast<unsigned char*>(a->GetPointData()->GetScalars()->GetVoidPointer(0));
  const unsigned char* pb = static_cast<unsigned char*>(b->GetPointData()->GetScalars()->GetVoidPointer(0));
  double sum = 0.0;
  vtkIdType within = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    if (mask && !(*mask)[static_cast<size_t>(i)])
    {
      continue;
    }
    int m = 0;
    for (int c = 0; c < 3; ++c)
    {
      const int d = std::abs(int(pa[3 * i + c]) - int(pb[3 * i + c]));
      sum += d;
      m = std::max(m, d);
    }
    within += m <= tolerance ? 1 : 0;
    r.Pixels++;
  }
  if (r.Pixels > 0)
  {
    r.Mean = sum / (3.0 * r.Pixels);
    r.Within = static_cast<double>(within) / r.Pixels;
  }
  return r;
}

/// |a - b| * 4, clamped, as an RGB image (for failing runs).
inline vtkSmartPointer<vtkImageData> DifferenceImage(vtkImageData* a, vtkImageData* b)
{
  auto d = vtkSmartPointer<vtkImageData>::New();
  d->DeepCopy(a);
  unsigned char* pd = static_cast<unsigned char*>(d->GetPointData()->GetScalars()->GetVoidPointer(0));
  const unsigned char* pa = static_cast<unsigned char*>(a->GetPointData()->GetScalars()->GetVoidPointer(0));
  const unsigned char* pb = static_cast<unsigned char*>(b->GetPointData()->GetScalars()->GetVoidPointer(0));
  const vtkIdType n = 3 * a->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i)
  {
    pd[i] = static_cast<unsigned char>(std::min(255, 4 * std::abs(int(pa[i]) - int(pb[i]))));
  }
  return d;
}

} // namespace cylvoltest

#endif
