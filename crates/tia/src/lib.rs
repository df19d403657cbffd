//! Transimpedance front end: gain, one pole, inversion, output rails
