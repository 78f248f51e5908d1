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
    // --- Improved Census (Paper only) ---
    // Gradient magnitude (grey levels per pixel, 3x3 Sobel / 8) above which a pixel uses the 7x7
    // window; at or below it the 9x9 window (textureless areas need more support). Paper: T, no
    // value given.
    double censusGradientThreshold = 6.0;
    // Half-width of the "no change" band around the trimmed-mean reference: a neighbour codes 10
    // when brighter than ref + alpha, 01 when darker than ref - alpha, 00 otherwise. Paper: 2.
    int censusAlpha = 2;
    // Canny hysteresis thresholds (3x3 Sobel, L2 gradient) for the edge bit of the four-bit code.
    double cannyLowThreshold = 40.0;
    double cannyHighThreshold = 100.0;
    // Harris corner bit: response > harrisThreshold * (largest response of the image). Paper: θ,
    // no value given. Block 3, Sobel aperture 3, k = 0.04 (the usual Harris constants).
    double harrisThreshold = 0.01;

    // --- Matching cost fusion, C = sum of (1 - exp(-C_x / lambda_x)) ---
    // Paper: C_cen is the Hamming distance of the four-bit codes (9x9 scale; 7x7 distances are
    // scaled by 80/48 so one lambda serves both windows), C_AD is the sum over R,G,B, C_grad the
    // mean over R,G,B of the gradient-magnitude difference.
    double lambdaCensus = 30.0;
    double lambdaAd = 30.0;       // the sum over three channels: Mei's 10 per channel-mean, times 3
    double lambdaGradient = 10.0;
    // AdCensus (Mei): 9x7 Census on grey, AD as the mean over R,G,B. Mei: 30 and 10.
    double meiLambdaCensus = 30.0;
    double meiLambdaAd = 10.0;

    // --- Cross-based support regions and aggregation (both; Mei's values) ---
    int crossTau1 = 20;           // colour limit for the whole arm (max over R,G,B)
    int crossTau2 = 6;            // tighter colour limit beyond crossL2
    int crossL1 = 34;             // longest arm, pixels
    int crossL2 = 17;             // arm length after which crossTau2 applies
    int crossIterations = 2;      // horizontal-then-vertical passes (Mei: 4, alternating)

    // --- Scanline optimisation along 8 directions (both; Mei's values, cost units) ---
    double scanlinePi1 = 1.0;
    double scanlinePi2 = 3.0;
    int scanlineTau = 15;         // colour difference deciding between Pi, Pi/4 and Pi/10

    // --- Refinement (both) ---
    int lrMaxDifference = 1;      // |D_L(p) - D_R(p - D_L(p))| <= this is consistent. Paper: δ = 1
    int votingIterations = 5;     // Mei: 5
    int votingMinCount = 20;      // tau_S: reliable pixels the region needs. Mei: 20
    double votingMinRatio = 0.4;  // tau_H: share of the most frequent disparity. Mei: 0.4
    // Sub-pixel: V fit on the aggregated cost, then 1-D Lucas-Kanade on the grey images to remove
    // the pixel locking the fit leaves (refinement.cpp explains; the volume depends on it).
    bool subpixelIntensityRefinement = true;
    int subpixelWindowRadius = 2;      // (2r+1)^2 window
    int subpixelIterations = 3;        // Gauss-Newton steps
    double subpixelMaxChange = 0.5;    // px away from the fitted value, else the fit stands
    bool medianFilter = true;     // Mei's final 3x3 median; removes isolated sub-pixel outliers

    // --- OpenCV StereoSGBM baseline (3-way mode) ---
    int sgbmBlockSize = 5;        // matched block size, odd
    bool sgbmFillHoles = true;    // fill invalid pixels from the nearest valid neighbour on the row,
                                  // as the reference figures in shared/data/README.md were measured
};

}  // namespace icewatch::stereo
