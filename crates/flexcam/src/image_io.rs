//! Writing frames: PNG colour, 16-bit PNG object ids, depth as OpenEXR or PFM.
