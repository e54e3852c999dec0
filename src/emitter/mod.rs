//! Emitters: directional, envmap, constant, point, spot (area emitters live with their shapes).
