#include "core/material.h"

#include "core/fcr.h"

void material_derive(Material *m)
{
    fcr_lame(m->E, m->nu, &m->mu, &m->lambda);
    m->stiffness = fcr_rest_stiffness(m->mu, m->lambda);
}
