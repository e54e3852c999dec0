//! Mitsuba 3 XML parser: text → ObjectDesc tree with positions.
