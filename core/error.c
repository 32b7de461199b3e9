#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>

static char g_message[1024];
static int g_has_message;

int mpm_error(int status, const char *fmt, ...)
{
    /* The first message of a failure is the most precise one; callers up the
     * stack only propagate the status. */
    if (!g_has_message) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(g_message, sizeof g_message, fmt, ap);
        va_end(ap);
        g_has_message = 1;
    }
    return status;
}

const char *mpm_last_error(void) { return g_has_message ? g_message : ""; }

void mpm_clear_error(void)
{
    g_has_message = 0;
    g_message[0] = '\0';
}
