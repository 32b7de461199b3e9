/* Floor guard (docs/design.md, floors): only experiments/render/ writes
 * PNG. This header shadows the real png.h in every other floor. */
#error "png.h outside experiments/: only the renderer writes pictures (docs/design.md, floors)"
