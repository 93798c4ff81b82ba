//! Quality measures (filled in by a helper).
