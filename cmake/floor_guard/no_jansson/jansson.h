/* Floor guard (docs/design.md, floors): only core/scene/ and experiments/
 * read JSON. This header shadows the real jansson.h in every other floor. */
#error "jansson.h in a floor that reads no JSON: JSON belongs to core/scene/ (loading) or experiments/ (docs/design.md, floors)"
