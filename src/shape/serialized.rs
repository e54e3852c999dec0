//! Mitsuba's `.serialized` mesh format loader.
