"""Features of a record, all read with ONE line rule and ONE demodulation-band rule.

==============  ==========================================================================
module          content
==============  ==========================================================================
``lines``       THE line rule (:func:`line_amplitude`: largest bin within
                f·(1 ± tolerance) ± 1.5 bins; :data:`EXACT_TOLERANCE`,
                :data:`SLIP_TOLERANCE`) and THE band rule (:func:`demodulation_band`)
``absolute``    :func:`extract_features` → :class:`FeatureRow`: GMF harmonics, sidebands,
                envelope-family amplitudes, statistics, labelled peaks (datasets, reports,
                the sideband baseline)
``envelope``    the envelope-families extractor: defect lines over their local median,
                family scores (the envelope baseline, sim-to-real, compare)
``sidebands``   shaft-rate sideband energies of the GMF harmonics on a mesh-tracked segment
``relative``    :func:`relative_features`: scale-free columns that compare a model with a
                measurement (``cmsim compare``), segment by segment
==============  ==========================================================================

References
----------
.. [1] R. B. Randall, *Vibration-based Condition Monitoring*, Wiley 2011, ch. 5-6.
"""

from cmsim.features.absolute import (ENVELOPE_FAMILIES, MIN_SIDEBAND_BINS, N_ENVELOPE_HARMONICS,
                                     N_GMF_HARMONICS, SIDEBAND_ORDERS, FeatureRow,
                                     LabelledLine, extract_features, gmf_levels, run_features,
                                     statistics)
from cmsim.features.envelope import (FAULT_FAMILIES, EnvelopeLine, band_bank_features,
                                     demodulated_spectrum, envelope_lines, family_scores,
                                     line_ratios)
from cmsim.features.lines import (EXACT_TOLERANCE, LINE_HALF_WIDTH_BINS, SLIP_TOLERANCE,
                                  demodulation_band, highest_fault_hz, line_amplitude,
                                  line_window)
from cmsim.features.relative import (N_ENVELOPE_BANDS, N_SHAPE_BANDS, band_column,
                                     band_family_columns, envelope_columns,
                                     relative_features, segment_features, segment_samples,
                                     segments)
from cmsim.features.sidebands import (MAX_SIDEBAND_ORDER, N_SIDEBAND_HARMONICS,
                                      SIDEBAND_HALF_WIDTH)

__all__ = ["FeatureRow", "LabelledLine", "extract_features", "run_features", "gmf_levels",
           "statistics", "relative_features", "envelope_columns", "band_family_columns",
           "band_column", "N_ENVELOPE_BANDS", "segment_features",
           "segments", "segment_samples",
           "line_amplitude", "line_window", "demodulation_band", "highest_fault_hz",
           "EnvelopeLine", "envelope_lines", "line_ratios", "family_scores",
           "demodulated_spectrum", "band_bank_features", "FAULT_FAMILIES",
           "N_GMF_HARMONICS", "SIDEBAND_ORDERS", "N_ENVELOPE_HARMONICS", "ENVELOPE_FAMILIES",
           "MIN_SIDEBAND_BINS", "N_SHAPE_BANDS", "N_SIDEBAND_HARMONICS", "SIDEBAND_HALF_WIDTH",
           "MAX_SIDEBAND_ORDER", "EXACT_TOLERANCE", "SLIP_TOLERANCE", "LINE_HALF_WIDTH_BINS"]
