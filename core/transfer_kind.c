/* The names of the transfers (core/transfer.h): the scene reader, bench and
 * the command line all read them here. */
#include <string.h>

#include "core/transfer.h"

const char *const transfer_names[] = {"apic", "mls", "pic_flip", NULL};
static const TransferKind named_kind[] = {TRANSFER_APIC, TRANSFER_MLS, TRANSFER_PIC_FLIP}; /* of transfer_names[i] */

_Static_assert(sizeof named_kind / sizeof named_kind[0] + 1 == sizeof transfer_names / sizeof transfer_names[0],
               "a kind for every name");

int transfer_kind_from_name(const char *name, TransferKind *kind)
{
    for (int i = 0; transfer_names[i]; ++i)
        if (!strcmp(name, transfer_names[i])) {
            *kind = named_kind[i];
            return 1;
        }
    return 0;
}

const char *transfer_kind_name(TransferKind kind)
{
    for (int i = 0; transfer_names[i]; ++i)
        if (named_kind[i] == kind) return transfer_names[i];
    return "?";
}
