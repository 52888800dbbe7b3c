// d'Eon 2011's Gaussian detector: the wrapped normal distribution on the circle (eq. 11).
#pragma once

namespace hairlut {

/// D_β(φ) = Σ_{k∈ℤ} g(β; φ − 2πk), g(β; x) = exp(−x²/(2β²)) / (√(2π) β)   (d'Eon 2011 eq. 11),
/// equivalently the Fourier series (1/2π)(1 + 2 Σ_{n≥1} e^{−n²β²/2} cos nφ).
/// Evaluated to full double precision: by the image sum for β < 2.5 (the images kept are those
/// within e^{−45} of the largest) and by the Fourier series for β ≥ 2.5 (terms down to e^{−45}).
/// Exactly even in φ and 2π-periodic; ∫_{−π}^{π} D_β dφ = 1.
/// Domain: β > 0 finite (radians), φ finite (any real). Result finite and ≥ 0.
double gaussian_detector(double beta, double phi);

}  // namespace hairlut
