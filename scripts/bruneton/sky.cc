// The sky of Bruneton's reference CPU model (atmosphere/reference, "Precomputed Atmospheric
// Scattering: a New Implementation", 2017) for terramp's comparison (docs/atmosphere.md): the
// atmosphere of his model_test.cc (Rayleigh 8 km, Mie 1.2 km with g 0.8, 300 DU of ozone in a
// tent from 10 to 40 km, ground albedo 0.1, the air 60 km thick), at the three wavelengths his
// spectra are reduced to here (440, 560 and 680 nm; the solar irradiance 1 at each, so radiances
// are per unit of it), printed as one line per (view altitude, sun elevation, view direction):
// altitude_m sun_deg view_elevation_deg view_azimuth_deg radiance_680 radiance_560 radiance_440.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "atmosphere/reference/model.h"

using namespace atmosphere::reference;

int main(int argc, char** argv) {
  const unsigned int orders = argc > 1 ? std::atoi(argv[1]) : 4;
  const std::string cache = argc > 2 ? argv[2] : "";
  const double kLambda[3] = {440.0, 560.0, 680.0};
  // model_test.cc's constants, and its tables' bins at 440, 560 and 680 nm.
  const double kRayleigh = 1.24062e-6;
  const double kMieBeta = 5.328e-3, kMieScaleHeight = 1200.0, kMieAlbedo = 0.9;
  const double kOzoneCrossSection[3] = {1.582e-26, 4.266e-25, 1.209e-25};
  const double kMaxOzone = 300.0 * 2.687e20 / 15000.0;
  std::vector<SpectralIrradiance> solar;
  std::vector<ScatteringCoefficient> rayleigh, mie_scattering, mie_extinction, ozone;
  for (int i = 0; i < 3; ++i) {
    const double lambda = kLambda[i] * 1e-3;
    solar.push_back(1.0 * watt_per_square_meter_per_nm);
    rayleigh.push_back(kRayleigh * std::pow(lambda, -4) / m);
    mie_scattering.push_back(kMieBeta / kMieScaleHeight * kMieAlbedo / m);
    mie_extinction.push_back(kMieBeta / kMieScaleHeight / m);
    ozone.push_back(kMaxOzone * kOzoneCrossSection[i] / m);
  }
  AtmosphereParameters a;
  a.solar_irradiance = IrradianceSpectrum(440.0 * nm, 680.0 * nm, solar);
  a.sun_angular_radius = 0.2678 * deg;
  a.bottom_radius = 6360.0 * km;
  a.top_radius = 6420.0 * km;
  a.rayleigh_density.layers[1] = DensityProfileLayer(0.0 * m, 1.0, -1.0 / (8000.0 * m), 0.0 / m, 0.0);
  a.rayleigh_scattering = ScatteringSpectrum(440.0 * nm, 680.0 * nm, rayleigh);
  a.mie_density.layers[1] = DensityProfileLayer(0.0 * m, 1.0, -1.0 / (kMieScaleHeight * m), 0.0 / m, 0.0);
  a.mie_scattering = ScatteringSpectrum(440.0 * nm, 680.0 * nm, mie_scattering);
  a.mie_extinction = ScatteringSpectrum(440.0 * nm, 680.0 * nm, mie_extinction);
  a.mie_phase_function_g = 0.8;
  a.absorption_density.layers[0] = DensityProfileLayer(25.0 * km, 0.0, 0.0 / km, 1.0 / (15.0 * km), -2.0 / 3.0);
  a.absorption_density.layers[1] = DensityProfileLayer(0.0 * km, 0.0, 0.0 / km, -1.0 / (15.0 * km), 8.0 / 3.0);
  a.absorption_extinction = ScatteringSpectrum(440.0 * nm, 680.0 * nm, ozone);
  a.ground_albedo = DimensionlessSpectrum(0.1);
  a.mu_s_min = cos(102.0 * deg);

  Model model(a, cache);
  model.Init(orders);
  const double kAltitudes[2] = {10.0, 10000.0};
  const double kSuns[7] = {2.0, 5.0, 10.0, 20.0, 40.0, 60.0, 90.0};
  // The zenith, and 2° and 10° above the horizon towards the sun, across and away from it.
  const double kViews[7][2] = {{90.0, 0.0}, {2.0, 0.0}, {2.0, 90.0}, {2.0, 180.0},
                               {10.0, 0.0}, {10.0, 90.0}, {10.0, 180.0}};
  for (double altitude : kAltitudes) {
    const Position camera(0.0 * m, 0.0 * m, a.bottom_radius + altitude * m);
    for (double sun : kSuns) {
      const double s = sun * M_PI / 180.0;
      const Direction sun_direction(std::cos(s), 0.0, std::sin(s));
      for (const auto& view : kViews) {
        const double e = view[0] * M_PI / 180.0, z = view[1] * M_PI / 180.0;
        const Direction ray(std::cos(e) * std::cos(z), std::cos(e) * std::sin(z), std::sin(e));
        DimensionlessSpectrum transmittance;
        RadianceSpectrum radiance = model.GetSkyRadiance(camera, ray, 0.0 * m, sun_direction, &transmittance);
        const auto unit = watt_per_square_meter_per_sr_per_nm;
        std::printf("%.0f %.0f %.0f %.0f %.6e %.6e %.6e\n", altitude, sun, view[0], view[1],
                    radiance(680.0 * nm).to(unit), radiance(560.0 * nm).to(unit), radiance(440.0 * nm).to(unit));
      }
    }
  }
  return 0;
}
