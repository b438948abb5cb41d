//! Piecewise-linear transfer functions (issue 3): breakpoints, extinction and
//! colour, emission models, presets, JSON and ParaView import.
