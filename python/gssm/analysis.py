"""Errors, NEES/NIS, metrics, bounds and identifiability as arrays."""
from . import _gssm

errors = _gssm.analysis.errors
metrics = _gssm.analysis.metrics
metrics_json = _gssm.analysis.metrics_json
cramer_rao = _gssm.analysis.cramer_rao
identifiability = _gssm.analysis.identifiability
chi2_quantile = _gssm.analysis.chi2_quantile
nees_interval = _gssm.analysis.nees_interval

__all__ = ["errors", "metrics", "metrics_json", "cramer_rao", "identifiability", "chi2_quantile", "nees_interval"]
