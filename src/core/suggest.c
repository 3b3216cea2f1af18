/* suggest.c: "did you mean" for unknown names (rl_options.h): the
 * Levenshtein distance (Levenshtein 1966) by the two-row dynamic programme
 * of Wagner & Fischer 1974, stopped once every cell of a row exceeds the
 * limit, which is all a suggestion needs. */
#include <ctype.h>
#include <string.h>

#include "rl/rl_options.h"

#define MAX_NAME 64   /* longer names are never suggested: no typo of a key */

int rl_edit_distance(const char *a, const char *b, int limit)
{
    if (!a || !b || limit < 0)
        return limit + 1;
    size_t n = strlen(a), m = strlen(b);
    if (n > MAX_NAME || m > MAX_NAME)
        return limit + 1;
    if ((n > m ? n - m : m - n) > (size_t)limit)
        return limit + 1;
    int prev[MAX_NAME + 1], cur[MAX_NAME + 1];
    for (size_t j = 0; j <= m; ++j)
        prev[j] = (int)j;
    for (size_t i = 1; i <= n; ++i) {
        cur[0] = (int)i;
        int row_min = cur[0];
        for (size_t j = 1; j <= m; ++j) {
            int same = tolower((unsigned char)a[i - 1]) == tolower((unsigned char)b[j - 1]);
            int d = prev[j - 1] + !same;                    /* keep or replace */
            d = prev[j] + 1 < d ? prev[j] + 1 : d;          /* delete a[i-1] */
            d = cur[j - 1] + 1 < d ? cur[j - 1] + 1 : d;    /* insert b[j-1] */
            cur[j] = d;
            row_min = d < row_min ? d : row_min;
        }
        if (row_min > limit)
            return limit + 1;
        memcpy(prev, cur, (m + 1) * sizeof *prev);
    }
    return prev[m] > limit ? limit + 1 : prev[m];
}

void rl_suggest(rl_suggestion *s, const char *typed, const char *known)
{
    if (!s || !typed || !known || !*known)
        return;
    int limit = strlen(known) <= 4 ? 1 : 2;
    int d = rl_edit_distance(typed, known, limit);
    if (d <= limit && (!s->name || d < s->distance)) {
        s->name = known;
        s->distance = d;
    }
}
