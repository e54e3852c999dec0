//! BSDFs (Mitsuba contract: `eval` includes the cosine, `sample` returns the weight f·cos/pdf).
