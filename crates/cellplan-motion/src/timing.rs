//! Move-time bounds and time parameterisation (filled in by the timing work).
