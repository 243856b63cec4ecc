//! Sheet-metal fittings (placeholder).
