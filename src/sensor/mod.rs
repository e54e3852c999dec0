//! Sensors and film: perspective camera, hdrfilm, reconstruction filters.
