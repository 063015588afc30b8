"""Fréchet distance between two sets of feature vectors (FID / FGD).

Heusel et al. 2017, "GANs Trained by a Two Time-Scale Update Rule Converge to a Local Nash
Equilibrium", Sec. 4 (FID): with Gaussians fitted to each set,

    d² = ‖μ_a − μ_b‖² + Tr(Σ_a + Σ_b − 2 (Σ_a Σ_b)^{1/2})

Used on motion-autoencoder features this is the Fréchet Gesture Distance (FGD) of Yoon et al.
2020, "Speech Gesture Generation from the Trimodal Context of Text, Audio, and Speaker Identity".
The encoder that produces the features is a separate, frozen component.
"""

from __future__ import annotations

import numpy as np


def gaussian_statistics(features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean (D,) and unbiased covariance (D, D) of features (N, D); N must be at least 2."""
    if features.ndim != 2 or features.shape[0] < 2:
        raise ValueError(f"features must be (N >= 2, D), got {features.shape}")
    features = features.astype(np.float64)
    return features.mean(axis=0), np.cov(features, rowvar=False).reshape(features.shape[1], features.shape[1])


def _psd_sqrt(matrix: np.ndarray) -> np.ndarray:
    """Symmetric square root of a symmetric positive semi-definite matrix (eigenvalues clipped at 0)."""
    from scipy import linalg  # here, not at the top: importing scipy takes seconds that a command's help never needs

    eigenvalues, eigenvectors = linalg.eigh(matrix)
    return (eigenvectors * np.sqrt(np.clip(eigenvalues, 0.0, None))) @ eigenvectors.T


def trace_sqrt_product(cov_a: np.ndarray, cov_b: np.ndarray) -> float:
    """Tr((Σ_a Σ_b)^{1/2}) computed as Tr((Σ_a^{1/2} Σ_b Σ_a^{1/2})^{1/2}).

    Σ_a Σ_b is similar to the symmetric PSD matrix Σ_a^{1/2} Σ_b Σ_a^{1/2}, so both have the same
    non-negative eigenvalues λ_i and the trace is Σ √λ_i. Unlike ``scipy.linalg.sqrtm`` of the
    non-symmetric product, this stays real and finite for singular (rank-deficient) covariances.
    """
    from scipy import linalg

    root_a = _psd_sqrt(cov_a)
    eigenvalues = linalg.eigvalsh(root_a @ cov_b @ root_a)
    return float(np.sqrt(np.clip(eigenvalues, 0.0, None)).sum())


def frechet_distance_from_statistics(mu_a: np.ndarray, cov_a: np.ndarray, mu_b: np.ndarray, cov_b: np.ndarray) -> float:
    """d² between N(μ_a, Σ_a) and N(μ_b, Σ_b) (the formula in the module docstring)."""
    diff = mu_a - mu_b
    distance = diff @ diff + np.trace(cov_a) + np.trace(cov_b) - 2.0 * trace_sqrt_product(cov_a, cov_b)
    return float(max(distance, 0.0))


def frechet_distance(features_a: np.ndarray, features_b: np.ndarray) -> float:
    """Fréchet distance between feature sets (N, D) and (M, D), e.g. real vs generated motion windows."""
    if features_a.shape[1:] != features_b.shape[1:]:
        raise ValueError(f"feature sizes differ: {features_a.shape} vs {features_b.shape}")
    return frechet_distance_from_statistics(*gaussian_statistics(features_a), *gaussian_statistics(features_b))
