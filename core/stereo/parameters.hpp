#pragma once

namespace icewatch::stereo {

// Every tunable of every matching method, with its documented default. Settable from the
// configuration file's "stereo" section (config/icewatch.json documents the same values).
//
// "Paper" is Wei et al., "Estimation of Wind Turbine Blade Icing Volume Based on Binocular Vision"
// (Appl. Sci. 2025, 15, 114); "Mei" is Mei et al., "On building an accurate stereo matching system
// on graphics hardware" (ICCV workshops 2011), the AD-Census baseline. Where neither paper gives a
// value the default was tuned on Middlebury Cones and Teddy (quarter size, 64 disparities).
struct Parameters {
    // --- Input (both) ---
    // Switching-median impulse removal: pixels more than this many grey levels from their 3x3
    // median take the median (impulse_filter.cpp). 0 switches it off. Not in either paper; measured
    // on Cones+Teddy (average bad): 12 % salt and pepper 10.9 % without, 5.5 % with; clean images
    // 4.72 % without, 4.74 % with.
    int impulseThreshold = 40;
    // An isolated pixel at 0 or 255 (no neighbour at the same value) is an impulse already when it
    // differs from its median by more than this: a white impulse on a bright wall stays within
    // impulseThreshold but still flips the Census bits of every window around it. Not in either
    // paper. Cones+Teddy average bad, 10 against 0: salt and pepper 3/6/9/12 % 4.09/4.23/4.36/4.78
    // -> 4.06/4.15/4.25/4.63 %, clean and Gaussian sigma 4-8 unchanged, Gaussian sigma 2 (whose
    // clipped pixels also sit at the rail) 5.42 -> 5.44 %. Any value from 5 to 15 measures the
    // same. 0 switches the rule off; only applies when impulseThreshold is on.
    int impulseRailThreshold = 10;
    // Noise-adaptive smoothing: each image's sensor noise is estimated (Immerkær's operator, the
    // 5th percentile of 8x8 block means, so texture does not count as noise) and the image is
    // blurred with a Gaussian of sigma = clamp(noiseSmoothingGain * (estimate - 1), 0, 0.8) when
    // that exceeds 0.2 (noise_smoothing.cpp). Clean Middlebury images estimate 0.7-1.25 and are
    // left alone; with Gaussian noise sigma 4/6/8 the Cones+Teddy average bad falls from
    // 7.26/8.68/12.73 % to 7.09/7.94/8.64 % (with the right-view pass below). When the flattest
    // 1 % of blocks still read more than one grey level of noise after that blur, the grey image
    // alone (Census, Canny and Harris input) goes through a bilateral filter whose range is three
    // noise estimates: noise on flat surfaces otherwise decides the Census bits there, and the
    // colour terms need no help. Clean and salt-and-pepper images (flattest 1 %: Cones 0.81-0.89,
    // Teddy 0.54-0.58) and sigma 6-8 (after the blur) are left alone; Cones+Teddy average bad at
    // Gaussian sigma 2 5.44 -> 5.09 %, sigma 4 6.79 -> 6.47 % (AD-Census 4.31 -> 4.11 % and
    // 5.62 -> 5.21 %). noise_smoothing.cpp explains. 0 switches both passes off.
    double noiseSmoothingGain = 0.3;
    // Range sigma of that bilateral pass, in noise estimates: 3 is about 2.2 noise sigmas, so noise
    // is averaged while a step of several sigmas keeps most of its contrast. Cones+Teddy average
    // bad over noise seeds 1, 3, 5, 7, 9 at Gaussian sigma 2 / 4: 5.21 / 6.88 % with 2, 5.04 /
    // 6.71 % with 3, 5.00 / 6.62 % with 4 (5.51 / 7.05 % without the pass). 0 switches the grey
    // pass alone off.
    double noiseGreyPassRange = 3.0;

    // --- Improved Census (Paper only) ---
    // Gradient magnitude (grey levels per pixel, 3x3 Sobel / 8) above which a pixel uses the 7x7
    // window; at or below it the 9x9 window (textureless areas need more support). Paper: T, no
    // value given. The trimmed-mean code of the larger window fattens edges more than it helps, so
    // the 9x9 window is kept to really flat pixels: 0.5 (2.4 % of Cones' and 5.4 % of Teddy's left
    // pixels; 8.2 % and 15.9 % with 1): Cones 3.47 -> 3.44 %, Teddy 5.67 -> 5.56 %, no noise row
    // worse (salt and pepper 3-12 % 0.01-0.07 points better, Gaussian σ 2-8 0-0.07 better).
    double censusGradientThreshold = 0.5;
    // Half-width of the "no change" band around the trimmed-mean reference: a neighbour codes 10
    // when brighter than ref + alpha, 01 when darker than ref - alpha, 00 otherwise. Paper: 2.
    // Default 1: on Middlebury's low-contrast texture 2 hides detail (Cones+Teddy average bad
    // 4.72 % with 1, 5.0 % with 2, 5.2 % with 0); the noise sweep was run with 1.
    int censusAlpha = 1;
    // The band follows the noise that is left after the smoothing below: alpha becomes
    // max(censusAlpha, round(censusAlphaNoiseGain * n)), n the mean of the two eyes' noise
    // estimates (estimateNoiseSigma, which reads about 3/4 of the noise's sigma, so the band is
    // about 1.1 sigma: noise no longer flips the bits of flat neighbours). Both eyes use the same
    // alpha, or their codes would not compare. Not in the paper. Teddy (estimate 0.7) keeps 1,
    // Cones (1.2, a noisier camera) and Gaussian sigma 2 get 2-3. Cones+Teddy average bad with
    // 1.5 against 0: clean 3.98 / 4.05 %, salt and pepper 3/6 % 4.09 / 4.13 and 4.23 / 4.29 %,
    // Gaussian sigma 2/4 5.42 / 5.57 and 6.91 / 7.10 %, no row worse. 0 keeps censusAlpha.
    double censusAlphaNoiseGain = 1.5;
    // Canny hysteresis thresholds (3x3 Sobel, L2 gradient) for the edge bit of the four-bit code.
    // A low threshold of 30 (was 40) lets weaker texture edges continue: Cones+Teddy average bad
    // 4.66 % against 4.69 %, both pairs better.
    double cannyLowThreshold = 30.0;
    double cannyHighThreshold = 100.0;
    // Harris corner bit: response > harrisThreshold * (largest response of the image). Paper: θ,
    // no value given. Block 3, Sobel aperture 3, k = 0.04 (the usual Harris constants). 0.001
    // (was 0.01): more corner bits make the code more discriminative on Middlebury's fine
    // texture; with the Canny change Cones 3.52 -> 3.47 %, Teddy 5.85 -> 5.76 %; Gaussian σ 4 and
    // 12 % salt and pepper unchanged within 0.1 point.
    double harrisThreshold = 0.001;

    // --- Matching cost fusion, C = sum of (1 - exp(-C_x / lambda_x)) ---
    // Paper: C_cen is the Hamming distance of the four-bit codes (9x9 scale; 7x7 distances are
    // scaled by 80/48 so one lambda serves both windows), C_AD is the sum over R,G,B, C_grad the
    // mean over R,G,B of the gradient-magnitude difference (grey levels per pixel). The paper
    // gives no values; these were tuned on Cones and Teddy (the gradient term is the most
    // informative one, hence its small lambda).
    double lambdaCensus = 15.0;
    double lambdaAd = 16.0;       // 20 before: Teddy 5.76 -> 5.67 %, Cones unchanged, noise rows within 0.05
    double lambdaGradient = 1.0;
    // AdCensus (Mei): 9x7 Census on grey, AD as the mean over R,G,B. Mei: 30 and 10.
    double meiLambdaCensus = 30.0;
    double meiLambdaAd = 10.0;

    // --- Cross-based support regions and aggregation (both) ---
    // Mei: τ1 20, τ2 6, L1 34, L2 17, 4 iterations. Tuned: tighter colour limits and one pass;
    // more passes over-smooth before the scanline optimisation (Cones+Teddy average bad rises
    // from 4.7 % with one pass to 4.85 % with two).
    int crossTau1 = 15;           // colour limit for the whole arm (max over R,G,B)
    int crossTau2 = 9;            // tighter colour limit beyond crossL2
    int crossL1 = 34;             // longest arm, pixels
    int crossL2 = 17;             // arm length after which crossTau2 applies
    int crossIterations = 1;      // horizontal-then-vertical passes

    // --- Scanline optimisation along 8 directions (both; cost units) ---
    // Mei: Π1 1, Π2 3, τ_SO 15 for his two-term cost; the paper's cost has three terms and less
    // aggregation before this step, and stronger smoothing was measured to pay off.
    double scanlinePi1 = 2.5;
    double scanlinePi2 = 7.0;
    int scanlineTau = 20;         // colour difference deciding between Pi, Pi/4 and Pi/10

    // --- Refinement (both) ---
    int lrMaxDifference = 1;      // |D_L(p) - D_R(p - D_L(p))| <= this is consistent. Paper: δ = 1
    // The right view's disparities for the check come from their own aggregation and scanline
    // pass over the right image (the cost volume read along its diagonals), as Mei et al. do.
    // Off, they are read off the left view's aggregated volume: about 1.2 times faster, but the
    // left image's support regions then judge the right view and many wrong pixels pass the
    // check. Cones+Teddy average bad: 3.90 % on, 4.43 % off.
    bool rightViewAggregation = true;
    // Scanline directions of that pass: 8, or the 4 along the axes. The right view only decides
    // which left pixels pass the check, and 4 directions measured better there, as well as faster:
    // Cones+Teddy average bad 3.90 % clean with 4, 3.98 % with 8 (salt-and-pepper 3 %: 3.96 /
    // 4.06 %; Gaussian σ 2: 5.44 / 5.44 %). The left view always takes all 8.
    int rightViewScanlineDirections = 4;
    int votingIterations = 5;     // Mei: 5
    int votingMinCount = 10;      // tau_S: reliable pixels the region needs. Mei: 20
    double votingMinRatio = 0.3;  // tau_H: share of the most frequent disparity. Mei: 0.4
    // Mei's depth-discontinuity adjustment after interpolation (refinement.cpp).
    bool discontinuityAdjustment = true;
    // Sub-pixel: V fit on the aggregated cost, then 1-D Lucas-Kanade on the grey images to remove
    // the pixel locking the fit leaves (refinement.cpp explains; the volume depends on it).
    bool subpixelIntensityRefinement = true;
    int subpixelWindowRadius = 2;      // (2r+1)^2 window
    int subpixelIterations = 2;        // Gauss-Newton steps (mean error < 0.02 px with 2)
    double subpixelMaxChange = 0.5;    // px away from the fitted value, else the fit stands
    bool medianFilter = true;     // Mei's final 3x3 median; removes isolated sub-pixel outliers

    // --- OpenCV StereoSGBM baseline (3-way mode) ---
    int sgbmBlockSize = 5;        // matched block size, odd
    bool sgbmFillHoles = true;    // fill invalid pixels from the nearest valid neighbour on the row,
                                  // as the reference figures in shared/data/README.md were measured
};

}  // namespace icewatch::stereo
