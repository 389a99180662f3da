"""Signal processing for condition monitoring: spectra, envelope, kurtogram, orders, TSA, labels.

All spectra are amplitude spectra (a sinusoid of amplitude A reads A, window-corrected).

==================  ==============================================================
module              content
==================  ==============================================================
``amplitude``       :func:`amplitude_spectrum`, :func:`welch_amplitude`, :class:`Spectrum`
``envelope``        :func:`bandpass`, :func:`envelope`, :func:`envelope_spectrum`
``kurtogram``       :func:`spectral_kurtosis`, :func:`kurtogram` (STFT-based)
``order``           :func:`angle_resample`, :func:`order_spectrum`, :func:`tacho_pulse_times`
``tsa``             :func:`time_synchronous_average`
``frequencies``     re-export of :mod:`cmsim.frequencies` (:class:`RigFrequencies`, ...)
``labels``          :func:`find_peaks`, :func:`label_peaks`, :func:`labelled_peaks`
``plots``           :func:`plot_spectrum`, :func:`plot_waterfall`, :func:`plot_orbit`,
                    :func:`plot_kurtogram` (matplotlib imported lazily, Agg canvas)
``run_spectrum``    :func:`run_spectrum` (labelled spectrum of a run signal), :class:`RunSpectrum`
``waterfall``       :func:`harmonic_amplitudes`, :func:`dominant_harmonic`,
                    :func:`plot_family_waterfall`, :func:`plot_harmonic_trend`
==================  ==============================================================
"""

from cmsim.spectra.amplitude import Spectrum, amplitude_spectrum, welch_amplitude
from cmsim.spectra.envelope import bandpass, envelope, envelope_spectrum
from cmsim.spectra.frequencies import (BearingFrequencies, RigFrequencies, bearing_frequencies,
                                       peak_families, rig_frequencies)
from cmsim.spectra.kurtogram import Kurtogram, kurtogram, spectral_kurtosis
from cmsim.spectra.labels import FamilyTemplate, find_peaks, label_peaks, labelled_peaks
from cmsim.spectra.order import (OrderSpectrum, angle_resample, order_spectrum, shaft_angle,
                                 tacho_pulse_times)
from cmsim.spectra.plots import plot_kurtogram, plot_orbit, plot_spectrum, plot_waterfall
from cmsim.spectra.run_spectrum import RunSpectrum, run_spectrum
from cmsim.spectra.tsa import SynchronousAverage, time_synchronous_average
from cmsim.spectra.waterfall import (dominant_harmonic, harmonic_amplitudes,
                                     plot_family_waterfall, plot_harmonic_trend)

__all__ = [
    "Spectrum", "amplitude_spectrum", "welch_amplitude",
    "bandpass", "envelope", "envelope_spectrum",
    "BearingFrequencies", "RigFrequencies", "bearing_frequencies", "rig_frequencies",
    "peak_families",
    "Kurtogram", "kurtogram", "spectral_kurtosis",
    "FamilyTemplate", "find_peaks", "label_peaks", "labelled_peaks",
    "OrderSpectrum", "angle_resample", "order_spectrum", "shaft_angle", "tacho_pulse_times",
    "plot_kurtogram", "plot_orbit", "plot_spectrum", "plot_waterfall",
    "SynchronousAverage", "time_synchronous_average",
    "RunSpectrum", "run_spectrum",
    "dominant_harmonic", "harmonic_amplitudes", "plot_family_waterfall", "plot_harmonic_trend",
]
