//! Paper-style PNG figures with a bundled font (no system fontconfig)
