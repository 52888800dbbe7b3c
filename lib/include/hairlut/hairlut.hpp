// Umbrella header: the whole hairlut physics library.
#pragma once

#include "hairlut/angles.hpp"
#include "hairlut/attenuation.hpp"
#include "hairlut/azimuthal_np.hpp"
#include "hairlut/bessel.hpp"
#include "hairlut/directional_albedo.hpp"
#include "hairlut/dual_scattering.hpp"
#include "hairlut/error.hpp"
#include "hairlut/fiber_geometry.hpp"
#include "hairlut/fresnel.hpp"
#include "hairlut/gaussian_detector.hpp"
#include "hairlut/hair_model.hpp"
#include "hairlut/lobe_energy.hpp"
#include "hairlut/longitudinal_mp.hpp"
#include "hairlut/quadrature.hpp"
#include "hairlut/version.hpp"
