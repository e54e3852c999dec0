//! Reading images (EXR, PNG) into float RGB(A) bitmaps.
