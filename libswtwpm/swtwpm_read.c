/* Reading a WPM CSV (docs/wpm-csv.md): every rule of the page checked, with the messages of
 * the Python reader (wpm_export/reader.py), "name:line: problem". Lines split and stripped as
 * Python's str.splitlines and str.strip (ASCII and the C1/Unicode line breaks), fields as
 * Python's csv module, numbers as Python's float() and int() (underscores between digits,
 * no hexadecimal), independent of the C locale. */
#include <ctype.h>
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "swtwpm_internal.h"

static const char *QUANTITY_NAMES[SWTWPM_N_QUANTITIES] = {"dp_n", "torque_nm", "sinkage_m",
                                                          "resistance_n", "dp_over_w"};
static const char *QUANTITY_UNITS[SWTWPM_N_QUANTITIES] = {"N", "N*m", "m", "N", "1"};
static const char *COLUMNS[] = {
    "soil", "wheel", "multipass", "load_n", "quantity", "unit", "degree", "slip_min",
    "slip_max", "a0", "a1", "a2", "a3", "a4", "a5", "a6", "a7", "n_points", "rmse",
    "step_below_zero", "slope_below_zero", "k95", "scatter_sd", "covariance"};
enum { C_SOIL, C_WHEEL, C_MULTIPASS, C_LOAD, C_QUANTITY, C_UNIT, C_DEGREE, C_SLIP_MIN,
       C_SLIP_MAX, C_A0, C_N_POINTS = 17, C_RMSE, C_STEP, C_SLOPE, C_K95, C_SCATTER, C_COV,
       N_COLUMNS };
static const char *WHEEL_KEYS[5] = {"radius_m", "width_m", "grouser_count", "grouser_height_m",
                                    "stiffness_n_per_mm"};
#define JSON_DEPTH 64

void wpm_message(char *msg, size_t msg_size, const char *format, ...)
{
    va_list args;
    if (!msg || !msg_size)
        return;
    va_start(args, format);
    vsnprintf(msg, msg_size, format, args);
    va_end(args);
}

const char *wpm_g(double x, char buffer[32])
{
    if (isnan(x))
        strcpy(buffer, "nan");
    else if (isinf(x))
        strcpy(buffer, x > 0 ? "inf" : "-inf");
    else
        snprintf(buffer, 32, "%g", x);
    return buffer;
}

/* Python's repr of a float: the shortest text that reads back to it */
void wpm_repr(double x, char buffer[40])
{
    int precision, exponent;
    char digits[40];
    if (!isfinite(x) || x == 0) {
        if (x == 0)
            strcpy(buffer, signbit(x) ? "-0.0" : "0.0");
        else
            wpm_g(x, buffer);
        return;
    }
    for (precision = 1; precision < 17; ++precision) {
        snprintf(digits, sizeof digits, "%.*e", precision - 1, x);
        if (strtod(digits, NULL) == x)
            break;
    }
    snprintf(digits, sizeof digits, "%.*e", precision - 1, x);
    exponent = atoi(strchr(digits, 'e') + 1);
    if (exponent < -4 || exponent >= 16) { /* 1e+16, 1.5e-05 */
        char *e = strchr(digits, 'e');
        if (precision == 1 && e[-1] == '.') /* never: %.0e has no point */
            e[-1] = 'e';
        strcpy(buffer, digits);
        return;
    }
    snprintf(buffer, 40, "%.*f", precision - 1 - exponent > 0 ? precision - 1 - exponent : 0, x);
    if (!strchr(buffer, '.'))
        strcat(buffer, ".0");
}

/* Python's repr of a str (UTF-8): single quotes unless it holds ' and no ", backslash
 * escapes of the quote, the backslash, \t \n \r and the other control characters (with
 * U+0080 ... U+00A0 and U+00AD, which Python does not print either); cut to size */
void wpm_repr_text(const char *s, char *buffer, size_t size)
{
    const unsigned char *c = (const unsigned char *)s;
    char quote = strchr(s, '\'') && !strchr(s, '"') ? '"' : '\'';
    size_t n = 0;
    if (!size)
        return;
#define PUT(ch) (n + 1 < size ? (void)(buffer[n++] = (char)(ch)) : (void)0)
    PUT(quote);
    for (; *c; ++c) {
        unsigned code = *c;
        if (code == 0xC2 && c[1] >= 0x80 && (c[1] <= 0xA0 || c[1] == 0xAD))
            code = *++c; /* U+0080 ... U+00A0, U+00AD */
        else if (code >= 0x80) {
            PUT(code);
            continue;
        }
        if (code == '\\' || code == (unsigned char)quote) {
            PUT('\\');
            PUT(code);
        } else if (code == '\t' || code == '\n' || code == '\r') {
            PUT('\\');
            PUT(code == '\t' ? 't' : code == '\n' ? 'n' : 'r');
        } else if (code < 0x20 || code >= 0x7F) {
            PUT('\\');
            PUT('x');
            PUT("0123456789abcdef"[code >> 4]);
            PUT("0123456789abcdef"[code & 15]);
        } else
            PUT(code);
    }
    PUT(quote);
#undef PUT
    buffer[n] = '\0';
}

const char *swtwpm_quantity_name(int quantity)
{
    return quantity >= 0 && quantity < SWTWPM_N_QUANTITIES ? QUANTITY_NAMES[quantity] : "?";
}

const char *swtwpm_quantity_unit(int quantity)
{
    return quantity >= 0 && quantity < SWTWPM_N_QUANTITIES ? QUANTITY_UNITS[quantity] : "?";
}

int swtwpm_quantity_index(const char *name)
{
    int q;
    for (q = 0; name && q < SWTWPM_N_QUANTITIES; ++q)
        if (!strcmp(name, QUANTITY_NAMES[q]))
            return q;
    return SWTWPM_E_ARGUMENT;
}

/* ---- text: UTF-8, lines, stripping ---- */

/* offset of the first invalid UTF-8 byte (as Python's strict decoder), or size */
static size_t utf8_invalid_at(const unsigned char *s, size_t size)
{
    size_t i = 0;
    while (i < size) {
        unsigned c = s[i];
        size_t n, k;
        unsigned lo = 0x80, hi = 0xBF;
        if (c < 0x80) {
            ++i;
            continue;
        }
        if (c >= 0xC2 && c <= 0xDF)
            n = 1;
        else if (c >= 0xE0 && c <= 0xEF) {
            n = 2;
            if (c == 0xE0)
                lo = 0xA0;
            if (c == 0xED)
                hi = 0x9F;
        } else if (c >= 0xF0 && c <= 0xF4) {
            n = 3;
            if (c == 0xF0)
                lo = 0x90;
            if (c == 0xF4)
                hi = 0x8F;
        } else
            return i;
        for (k = 1; k <= n; ++k) {
            unsigned b;
            if (i + k >= size)
                return i;
            b = s[i + k];
            if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF))
                return i;
        }
        i += n + 1;
    }
    return size;
}

/* length of a line break starting at s (as str.splitlines), 0 if none */
static size_t line_break(const unsigned char *s, const unsigned char *end)
{
    if (s >= end)
        return 0;
    if (*s == '\r')
        return (s + 1 < end && s[1] == '\n') ? 2 : 1;
    if (*s == '\n' || *s == 0x0B || *s == 0x0C || (*s >= 0x1C && *s <= 0x1E))
        return 1;
    if (*s == 0xC2 && s + 1 < end && s[1] == 0x85)
        return 2;
    if (*s == 0xE2 && s + 2 < end && s[1] == 0x80 && (s[2] == 0xA8 || s[2] == 0xA9))
        return 3;
    return 0;
}

/* whitespace as str.strip (ASCII, the separators 0x1C-0x1F, NEL and NBSP) */
static size_t space_at(const unsigned char *s, const unsigned char *end)
{
    if (s >= end)
        return 0;
    if (*s == ' ' || (*s >= 0x09 && *s <= 0x0D) || (*s >= 0x1C && *s <= 0x1F))
        return 1;
    if (*s == 0xC2 && s + 1 < end && (s[1] == 0x85 || s[1] == 0xA0))
        return 2;
    return 0;
}

static size_t space_before(const unsigned char *begin, const unsigned char *end)
{
    if (end > begin && (end[-1] == ' ' || (end[-1] >= 0x09 && end[-1] <= 0x0D)
                        || (end[-1] >= 0x1C && end[-1] <= 0x1F)))
        return 1;
    if (end - begin >= 2 && end[-2] == 0xC2 && (end[-1] == 0x85 || end[-1] == 0xA0))
        return 2;
    return 0;
}

/* a copy of [begin, end) stripped, NUL-terminated (NULL: out of memory) */
static char *strip_copy(const char *begin, const char *end)
{
    const unsigned char *b = (const unsigned char *)begin, *e = (const unsigned char *)end;
    size_t n;
    char *out;
    while ((n = space_at(b, e)) != 0)
        b += n;
    while (e > b && (n = space_before(b, e)) != 0)
        e -= n;
    out = malloc((size_t)(e - b) + 1);
    if (out) {
        memcpy(out, b, (size_t)(e - b));
        out[e - b] = '\0';
    }
    return out;
}

/* ---- CSV fields of one line (Python csv, excel dialect, non-strict) ---- */

typedef struct {
    int n, capacity;
    char **field;
} fields_t;

static void fields_free(fields_t *f)
{
    int i;
    for (i = 0; i < f->n; ++i)
        free(f->field[i]);
    free(f->field);
    f->n = f->capacity = 0;
    f->field = NULL;
}

static int fields_push(fields_t *f, const char *text, size_t length)
{
    char *copy;
    if (f->n == f->capacity) {
        int capacity = f->capacity ? 2 * f->capacity : 32;
        char **grown = realloc(f->field, (size_t)capacity * sizeof *grown);
        if (!grown)
            return 0;
        f->field = grown;
        f->capacity = capacity;
    }
    copy = strip_copy(text, text + length);
    if (!copy)
        return 0;
    f->field[f->n++] = copy;
    return 1;
}

/* fields of line [begin, end), each stripped; 0 on out of memory */
static int split_csv(const char *begin, const char *end, fields_t *out)
{
    size_t capacity = (size_t)(end - begin) + 1, n = 0;
    char *buffer = malloc(capacity);
    enum { START, FIELD, QUOTED, QUOTE_IN_QUOTED } state = START;
    const char *c;
    int ok = 1;
    if (!buffer)
        return 0;
    for (c = begin; c < end && ok; ++c) {
        switch (state) {
        case START:
            if (*c == '"')
                state = QUOTED;
            else if (*c == ',')
                ok = fields_push(out, buffer, n), n = 0;
            else
                buffer[n++] = *c, state = FIELD;
            break;
        case FIELD:
            if (*c == ',')
                ok = fields_push(out, buffer, n), n = 0, state = START;
            else
                buffer[n++] = *c;
            break;
        case QUOTED:
            if (*c == '"')
                state = QUOTE_IN_QUOTED;
            else
                buffer[n++] = *c;
            break;
        case QUOTE_IN_QUOTED:
            if (*c == '"')
                buffer[n++] = '"', state = QUOTED;
            else if (*c == ',')
                ok = fields_push(out, buffer, n), n = 0, state = START;
            else
                buffer[n++] = *c, state = FIELD;
            break;
        }
    }
    if (ok)
        ok = fields_push(out, buffer, n);
    free(buffer);
    return ok;
}

/* ---- numbers as Python's float() and int() ---- */

static int lower_equal(const char *s, const char *word)
{
    for (; *s && *word; ++s, ++word)
        if (tolower((unsigned char)*s) != *word)
            return 0;
    return !*s && !*word;
}

/* digits with single underscores between them: copied without the underscores; the end */
static const char *digits(const char *s, char **out, int *count)
{
    *count = 0;
    while (isdigit((unsigned char)*s)) {
        *(*out)++ = *s++;
        ++*count;
        if (*s == '_' && isdigit((unsigned char)s[1]))
            ++s;
    }
    return s;
}

/* 1: a finite number in *value; 0: not a number; -1: not finite; -2: out of memory */
static int parse_float(const char *text, double *value)
{
    const char *s = text, *sign_end;
    char *buffer, *o;
    int n_int, n_frac = 0, n_exp, result = 1;
    size_t length = strlen(text);
    char point = localeconv()->decimal_point[0];
    if (!length)
        return 0;
    buffer = malloc(length + 2);
    if (!buffer)
        return -2;
    o = buffer;
    if (*s == '+' || *s == '-')
        *o++ = *s++;
    sign_end = s;
    if (lower_equal(sign_end, "inf") || lower_equal(sign_end, "infinity")
        || lower_equal(sign_end, "nan")) {
        free(buffer);
        return -1;
    }
    s = digits(s, &o, &n_int);
    if (*s == '.') {
        *o++ = point ? point : '.';
        s = digits(s + 1, &o, &n_frac);
    }
    if (n_int + n_frac == 0)
        result = 0;
    else if (*s == 'e' || *s == 'E') {
        *o++ = 'e';
        ++s;
        if (*s == '+' || *s == '-')
            *o++ = *s++;
        s = digits(s, &o, &n_exp);
        if (!n_exp)
            result = 0;
    }
    *o = '\0';
    if (result && *s)
        result = 0;
    if (result) {
        *value = strtod(buffer, NULL);
        if (!isfinite(*value))
            result = -1;
    }
    free(buffer);
    return result;
}

/* 1: an integer in *value; 0: not an integer; -1: too large */
static int parse_integer(const char *text, long long *value)
{
    const char *s = text;
    int negative = 0, count = 0;
    unsigned long long v = 0;
    if (*s == '+' || *s == '-')
        negative = *s++ == '-';
    while (isdigit((unsigned char)*s)) {
        unsigned d = (unsigned)(*s++ - '0');
        if (v > (9223372036854775807ULL - d) / 10)
            return -1;
        v = v * 10 + d;
        ++count;
        if (*s == '_' && isdigit((unsigned char)s[1]))
            ++s;
    }
    if (!count || *s)
        return 0;
    *value = negative ? -(long long)v : (long long)v;
    return 1;
}

/* ---- the reader ---- */

typedef struct {
    const char *name;
    int line;
    char *msg;
    size_t msg_size;
} context_t;

static int problem(const context_t *ctx, const char *format, ...)
{
    char text[768];
    va_list args;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    wpm_message(ctx->msg, ctx->msg_size, "%s:%d: %s", ctx->name, ctx->line, text);
    return SWTWPM_E_FORMAT;
}

static int number(const context_t *ctx, const char *text, const char *column, double *value)
{
    int r = parse_float(text, value);
    if (r == -2)
        return SWTWPM_E_MEMORY;
    if (r == 0)
        return problem(ctx, "%s '%s' is not a number", column, text);
    if (r == -1)
        return problem(ctx, "%s '%s' is not finite", column, text);
    return 0;
}

static int integer(const context_t *ctx, const char *text, const char *column, long long *value)
{
    int r = parse_integer(text, value);
    if (r == 0)
        return problem(ctx, "%s '%s' is not an integer", column, text);
    if (r == -1)
        return problem(ctx, "%s '%s' is too large", column, text);
    return 0;
}

#define TRY(call)            \
    do {                     \
        int r_ = (call);     \
        if (r_ < 0)          \
            return r_;       \
    } while (0)

static char *duplicate(const char *s)
{
    char *out = malloc(strlen(s) + 1);
    if (out)
        strcpy(out, s);
    return out;
}

/* the uncertainty columns of a row (reader.py _uncertainty) */
static int uncertainty(const context_t *ctx, char **field, int n_columns, wpm_row *row)
{
    const char *k95 = n_columns > C_K95 ? field[C_K95] : "";
    const char *scatter = n_columns > C_SCATTER ? field[C_SCATTER] : "";
    const char *cov = n_columns > C_COV ? field[C_COV] : "";
    int m = row->degree + 3, count = 0, i, j, need = m * (m + 1) / 2;
    double upper[SWTWPM_MAX_PARAMETERS * (SWTWPM_MAX_PARAMETERS + 1) / 2];
    const char *s = cov;
    if (!*k95 && !*scatter && !*cov)
        return 0;
    if (!*k95 || !*scatter || !*cov)
        return problem(ctx, "k95, scatter_sd, covariance: give all three or none");
    TRY(number(ctx, k95, "k95", &row->k95));
    TRY(number(ctx, scatter, "scatter_sd", &row->scatter_sd));
    if (!(row->k95 > 0) || row->scatter_sd < 0) {
        char a[32], b[32];
        return problem(ctx, "k95 %s must be > 0 and scatter_sd %s >= 0", wpm_g(row->k95, a),
                       wpm_g(row->scatter_sd, b));
    }
    for (;;) { /* str.split(): runs of whitespace */
        const char *begin, *end;
        size_t n;
        char *token;
        double v;
        int r;
        while ((n = space_at((const unsigned char *)s, (const unsigned char *)s + strlen(s))))
            s += n;
        if (!*s)
            break;
        begin = s;
        while (*s && !space_at((const unsigned char *)s, (const unsigned char *)s + strlen(s)))
            ++s;
        end = s;
        token = malloc((size_t)(end - begin) + 1);
        if (!token)
            return SWTWPM_E_MEMORY;
        memcpy(token, begin, (size_t)(end - begin));
        token[end - begin] = '\0';
        r = number(ctx, token, "covariance", &v);
        free(token);
        if (r < 0)
            return r;
        if (count < need)
            upper[count] = v;
        ++count;
    }
    if (count != need)
        return problem(ctx, "covariance has %d numbers; degree %d needs %d (upper triangle of "
                       "%d x %d)", count, row->degree, need, m, m);
    count = 0;
    for (i = 0; i < m; ++i)
        for (j = i; j < m; ++j) {
            row->covariance[i][j] = row->covariance[j][i] = upper[count++];
        }
    for (i = 0; i < m; ++i)
        if (row->covariance[i][i] < 0)
            return problem(ctx, "covariance has a negative variance on its diagonal");
    row->has_uncertainty = 1;
    return 0;
}

/* one data row -> curve, every rule of the page checked (reader.py _curve) */
static int parse_row(const context_t *ctx, fields_t *f, int n_columns, wpm_row *row)
{
    char **field = f->field;
    long long degree, multipass, n_points;
    int q, i;
    char a[32], b[32];
    memset(row, 0, sizeof *row);
    row->k95 = row->scatter_sd = NAN;
    row->line = ctx->line;
    if (f->n != n_columns)
        return problem(ctx, "%d fields, the format has %d", f->n, n_columns);
    if (!*field[C_SOIL] || !*field[C_WHEEL])
        return problem(ctx, "soil and wheel must not be empty");
    q = swtwpm_quantity_index(field[C_QUANTITY]);
    if (q < 0)
        return problem(ctx, "unknown quantity '%s'; known: dp_n, torque_nm, sinkage_m, "
                       "resistance_n, dp_over_w", field[C_QUANTITY]);
    if (strcmp(field[C_UNIT], QUANTITY_UNITS[q]))
        return problem(ctx, "unit '%s' for %s; the format says '%s'", field[C_UNIT],
                       QUANTITY_NAMES[q], QUANTITY_UNITS[q]);
    TRY(integer(ctx, field[C_DEGREE], "degree", &degree));
    if (degree < 3 || degree > 7)
        return problem(ctx, "degree %lld outside 3-7", degree);
    TRY(integer(ctx, field[C_MULTIPASS], "multipass", &multipass));
    TRY(number(ctx, field[C_LOAD], "load_n", &row->load_n));
    TRY(number(ctx, field[C_SLIP_MIN], "slip_min", &row->slip_min));
    TRY(number(ctx, field[C_SLIP_MAX], "slip_max", &row->slip_max));
    if (multipass < 0 || row->load_n <= 0)
        return problem(ctx, "multipass %lld must be >= 0 and load_n %s > 0", multipass,
                       wpm_g(row->load_n, a));
    if (!(-1.0 <= row->slip_min && row->slip_min < row->slip_max && row->slip_max <= 1.0))
        return problem(ctx, "slip range [%s, %s]: need -1 <= slip_min < slip_max <= 1",
                       wpm_g(row->slip_min, a), wpm_g(row->slip_max, b));
    row->degree = (int)degree;
    for (i = 0; i <= row->degree; ++i)
        TRY(number(ctx, field[C_A0 + i], COLUMNS[C_A0 + i], &row->a[i]));
    for (i = row->degree + 1; i <= SWTWPM_MAX_DEGREE; ++i) {
        double v;
        if (!*field[C_A0 + i])
            continue;
        TRY(number(ctx, field[C_A0 + i], COLUMNS[C_A0 + i], &v));
        if (v != 0.0)
            return problem(ctx, "%s = %s beyond degree %d (must be empty or 0)",
                           COLUMNS[C_A0 + i], field[C_A0 + i], row->degree);
    }
    TRY(integer(ctx, field[C_N_POINTS], "n_points", &n_points));
    if (n_points < degree + 1)
        return problem(ctx, "n_points %lld < degree + 1 = %d: underdetermined fit", n_points,
                       row->degree + 1);
    TRY(number(ctx, field[C_RMSE], "rmse", &row->step)); /* rmse: checked, not kept */
    if (row->step < 0)
        return problem(ctx, "rmse %s < 0", wpm_g(row->step, a));
    row->step = 0.0;
    if (n_columns > C_SLOPE) {
        TRY(number(ctx, field[C_STEP], "step_below_zero", &row->step));
        TRY(number(ctx, field[C_SLOPE], "slope_below_zero", &row->slope));
    }
    TRY(uncertainty(ctx, field, n_columns, row));
    row->quantity = q;
    row->multipass = multipass;
    row->soil = duplicate(field[C_SOIL]);
    row->wheel = duplicate(field[C_WHEEL]);
    return row->soil && row->wheel ? 0 : SWTWPM_E_MEMORY;
}

/* ---- JSON (the wheel_geometry header) ---- */

enum { J_NULL, J_BOOL, J_NUMBER, J_STRING, J_ARRAY, J_OBJECT };

typedef struct json {
    int type, n;
    double number;
    char *string;      /* J_STRING (UTF-8, NUL-terminated; may contain NUL escapes) */
    char **keys;       /* J_OBJECT */
    struct json *item; /* J_ARRAY, J_OBJECT */
} json;

typedef struct {
    const char *s, *begin, *end;
    char error[96];
} json_reader;

static void json_free(json *v)
{
    int i;
    if (!v)
        return;
    for (i = 0; i < v->n; ++i) {
        json_free(&v->item[i]);
        if (v->keys)
            free(v->keys[i]);
    }
    free(v->item);
    free(v->keys);
    free(v->string);
    memset(v, 0, sizeof *v);
}

static int json_fail(json_reader *r, const char *what)
{
    if (!r->error[0])
        snprintf(r->error, sizeof r->error, "%s at char %d", what, (int)(r->s - r->begin));
    return 0;
}

static void json_space(json_reader *r)
{
    while (r->s < r->end && (*r->s == ' ' || *r->s == '\t' || *r->s == '\n' || *r->s == '\r'))
        ++r->s;
}

static int hex4(const char *s, const char *end, unsigned *out)
{
    int i;
    *out = 0;
    if (end - s < 4)
        return 0;
    for (i = 0; i < 4; ++i) {
        int c = (unsigned char)s[i];
        *out <<= 4;
        if (c >= '0' && c <= '9')
            *out |= (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f')
            *out |= (unsigned)(c - 'a' + 10);
        else if (c >= 'A' && c <= 'F')
            *out |= (unsigned)(c - 'A' + 10);
        else
            return 0;
    }
    return 1;
}

static int json_string(json_reader *r, char **out)
{
    size_t n = 0;
    char *buffer = malloc((size_t)(r->end - r->s) * 2 + 4);
    if (!buffer)
        return json_fail(r, "out of memory");
    ++r->s; /* the opening quote */
    while (r->s < r->end && *r->s != '"') {
        unsigned char c = (unsigned char)*r->s;
        if (c < 0x20) {
            free(buffer);
            return json_fail(r, "invalid control character");
        }
        if (c != '\\') {
            buffer[n++] = (char)c;
            ++r->s;
            continue;
        }
        if (++r->s >= r->end)
            break;
        switch (*r->s) {
        case '"': case '\\': case '/':
            buffer[n++] = *r->s++;
            break;
        case 'b': buffer[n++] = '\b'; ++r->s; break;
        case 'f': buffer[n++] = '\f'; ++r->s; break;
        case 'n': buffer[n++] = '\n'; ++r->s; break;
        case 'r': buffer[n++] = '\r'; ++r->s; break;
        case 't': buffer[n++] = '\t'; ++r->s; break;
        case 'u': {
            unsigned u, low;
            if (!hex4(r->s + 1, r->end, &u)) {
                free(buffer);
                return json_fail(r, "invalid \\uXXXX escape");
            }
            r->s += 5;
            if (u >= 0xD800 && u < 0xDC00 && r->end - r->s >= 6 && r->s[0] == '\\'
                && r->s[1] == 'u' && hex4(r->s + 2, r->end, &low) && low >= 0xDC00
                && low < 0xE000) {
                u = 0x10000 + ((u - 0xD800) << 10) + (low - 0xDC00);
                r->s += 6;
            }
            if (u < 0x80)
                buffer[n++] = (char)u;
            else if (u < 0x800) {
                buffer[n++] = (char)(0xC0 | (u >> 6));
                buffer[n++] = (char)(0x80 | (u & 0x3F));
            } else if (u < 0x10000) {
                buffer[n++] = (char)(0xE0 | (u >> 12));
                buffer[n++] = (char)(0x80 | ((u >> 6) & 0x3F));
                buffer[n++] = (char)(0x80 | (u & 0x3F));
            } else {
                buffer[n++] = (char)(0xF0 | (u >> 18));
                buffer[n++] = (char)(0x80 | ((u >> 12) & 0x3F));
                buffer[n++] = (char)(0x80 | ((u >> 6) & 0x3F));
                buffer[n++] = (char)(0x80 | (u & 0x3F));
            }
            break;
        }
        default:
            free(buffer);
            return json_fail(r, "invalid \\escape");
        }
    }
    if (r->s >= r->end) {
        free(buffer);
        return json_fail(r, "unterminated string");
    }
    ++r->s;
    buffer[n] = '\0';
    *out = buffer;
    return 1;
}

static int json_value(json_reader *r, json *v, int depth);

static int json_push(json_reader *r, json *v, char *key)
{
    if ((v->n & (v->n - 1)) == 0) { /* capacity: powers of two */
        int capacity = v->n ? 2 * v->n : 1;
        json *items = realloc(v->item, (size_t)capacity * sizeof *items);
        if (!items)
            return free(key), json_fail(r, "out of memory");
        v->item = items;
        if (v->type == J_OBJECT) {
            char **keys = realloc(v->keys, (size_t)capacity * sizeof *keys);
            if (!keys)
                return free(key), json_fail(r, "out of memory");
            v->keys = keys;
        }
    }
    memset(&v->item[v->n], 0, sizeof *v->item);
    if (v->type == J_OBJECT)
        v->keys[v->n] = key;
    ++v->n;
    return 1;
}

static int json_container(json_reader *r, json *v, int depth)
{
    char close = *r->s == '{' ? '}' : ']';
    v->type = close == '}' ? J_OBJECT : J_ARRAY;
    ++r->s;
    json_space(r);
    if (r->s < r->end && *r->s == close) {
        ++r->s;
        return 1;
    }
    for (;;) {
        char *key = NULL;
        json_space(r);
        if (v->type == J_OBJECT) {
            if (r->s >= r->end || *r->s != '"')
                return json_fail(r, "expecting property name enclosed in double quotes");
            if (!json_string(r, &key))
                return 0;
            json_space(r);
            if (r->s >= r->end || *r->s != ':')
                return free(key), json_fail(r, "expecting ':' delimiter");
            ++r->s;
        }
        if (!json_push(r, v, key) || !json_value(r, &v->item[v->n - 1], depth + 1))
            return 0;
        json_space(r);
        if (r->s < r->end && *r->s == ',') {
            ++r->s;
            continue;
        }
        if (r->s < r->end && *r->s == close) {
            ++r->s;
            return 1;
        }
        return json_fail(r, "expecting ',' delimiter");
    }
}

static int json_literal(json_reader *r, const char *word)
{
    size_t n = strlen(word);
    if ((size_t)(r->end - r->s) >= n && !strncmp(r->s, word, n)) {
        r->s += n;
        return 1;
    }
    return 0;
}

static int json_value(json_reader *r, json *v, int depth)
{
    const char *start;
    char buffer[400];
    json_space(r);
    if (depth > JSON_DEPTH)
        return json_fail(r, "nested too deeply");
    if (r->s >= r->end)
        return json_fail(r, "expecting value");
    if (*r->s == '{' || *r->s == '[')
        return json_container(r, v, depth);
    if (*r->s == '"') {
        v->type = J_STRING;
        return json_string(r, &v->string);
    }
    if (json_literal(r, "null")) {
        v->type = J_NULL;
        return 1;
    }
    if (json_literal(r, "true") || json_literal(r, "false")) {
        v->type = J_BOOL;
        v->number = r->s[-1] == 'e' && r->s[-2] == 'u';
        return 1;
    }
    v->type = J_NUMBER; /* Python's json also reads NaN, Infinity, -Infinity */
    if (json_literal(r, "NaN")) {
        v->number = NAN;
        return 1;
    }
    if (json_literal(r, "Infinity") || json_literal(r, "-Infinity")) {
        v->number = r->s[-9] == '-' ? -INFINITY : INFINITY;
        return 1;
    }
    start = r->s;
    if (r->s < r->end && *r->s == '-')
        ++r->s;
    if (r->s < r->end && *r->s == '0')
        ++r->s;
    else if (r->s < r->end && *r->s >= '1' && *r->s <= '9')
        while (r->s < r->end && isdigit((unsigned char)*r->s))
            ++r->s;
    else
        return json_fail(r, "expecting value");
    if (r->s + 1 < r->end && *r->s == '.' && isdigit((unsigned char)r->s[1])) {
        ++r->s;
        while (r->s < r->end && isdigit((unsigned char)*r->s))
            ++r->s;
    }
    if (r->s < r->end && (*r->s == 'e' || *r->s == 'E')) {
        const char *e = r->s + 1;
        if (e < r->end && (*e == '+' || *e == '-'))
            ++e;
        if (e < r->end && isdigit((unsigned char)*e)) {
            r->s = e;
            while (r->s < r->end && isdigit((unsigned char)*r->s))
                ++r->s;
        }
    }
    if ((size_t)(r->s - start) >= sizeof buffer) {
        v->number = start[0] == '-' ? -INFINITY : INFINITY; /* absurdly long: not finite */
        return 1;
    }
    memcpy(buffer, start, (size_t)(r->s - start));
    buffer[r->s - start] = '\0';
    if (parse_float(buffer, &v->number) != 1)
        v->number = INFINITY;
    return 1;
}

/* Validate one wheel's geometry as swtlab_base.domain.Wheel; 0 or a format error. */
static int wheel_values(const context_t *ctx, const char *name, const json *entry,
                        double geometry[5])
{
    int i, k;
    char missing[160] = "", unknown[400] = "";
    const json *value[5] = {NULL, NULL, NULL, NULL, NULL};
    for (i = 0; i < entry->n; ++i) { /* the last of duplicate keys counts, as in Python */
        for (k = 0; k < 5; ++k)
            if (!strcmp(entry->keys[i], WHEEL_KEYS[k]))
                break;
        if (k < 5)
            value[k] = &entry->item[i];
        else if (strlen(unknown) + strlen(entry->keys[i]) + 8 < sizeof unknown) {
            strcat(unknown, *unknown ? ", '" : "'");
            strcat(unknown, entry->keys[i]);
            strcat(unknown, "'");
        }
    }
    for (k = 0; k < 5; ++k)
        if (!value[k]) {
            strcat(missing, *missing ? ", '" : "'");
            strcat(missing, WHEEL_KEYS[k]);
            strcat(missing, "'");
        }
    if (*missing || *unknown)
        return problem(ctx, "wheel_geometry of wheel '%s': missing [%s], unknown [%s]", name,
                       missing, unknown);
    for (k = 0; k < 5; ++k) {
        const json *v = value[k];
        double x = v->number;
        char g[32];
        if (k == 4 && v->type == J_NULL) {
            geometry[k] = NAN;
            continue;
        }
        if (k == 2) {
            if (v->type != J_NUMBER || !isfinite(x) || x != floor(x) || x < 0)
                return problem(ctx, "wheel_geometry: wheel grouser_count must be an integer "
                               ">= 0");
        } else if (v->type != J_NUMBER || !isfinite(x))
            return problem(ctx, "wheel_geometry: wheel %s must be a finite number",
                           WHEEL_KEYS[k]);
        else if (k == 3 ? x < 0 : x <= 0)
            return problem(ctx, "wheel_geometry: wheel %s %s must be %s 0", WHEEL_KEYS[k],
                           wpm_g(x, g), k == 3 ? ">=" : ">");
        geometry[k] = x;
    }
    return 0;
}

/* The wheel_geometry header (reader.py wheel_geometry): wheels into the model. */
static int wheel_geometry(swtwpm *model, const char *text, const context_t *ctx)
{
    json_reader r;
    json root;
    int i, result = 0;
    memset(&root, 0, sizeof root);
    memset(&r, 0, sizeof r);
    r.s = r.begin = text;
    r.end = text + strlen(text);
    if (!json_value(&r, &root, 0) || (json_space(&r), r.s != r.end)) {
        if (!r.error[0])
            json_fail(&r, "extra data");
        json_free(&root);
        return problem(ctx, "wheel_geometry is not JSON: %s", r.error);
    }
    if (root.type != J_OBJECT)
        result = -1;
    for (i = 0; !result && i < root.n; ++i)
        if (root.item[i].type != J_OBJECT)
            result = -1;
    if (result) {
        json_free(&root);
        return problem(ctx, "wheel_geometry must map each wheel name to its radius_m, width_m, "
                       "grouser_count, grouser_height_m, stiffness_n_per_mm");
    }
    model->wheels = calloc((size_t)root.n + 1, sizeof *model->wheels);
    if (!model->wheels)
        result = SWTWPM_E_MEMORY;
    for (i = 0; !result && i < root.n; ++i) {
        int w;
        double geometry[5];
        result = wheel_values(ctx, root.keys[i], &root.item[i], geometry);
        if (result)
            break;
        for (w = 0; w < model->n_wheels; ++w)
            if (!strcmp(model->wheels[w].name, root.keys[i]))
                break;
        if (w == model->n_wheels) {
            model->wheels[w].name = duplicate(root.keys[i]);
            if (!model->wheels[w].name) {
                result = SWTWPM_E_MEMORY;
                break;
            }
            ++model->n_wheels;
        }
        memcpy(model->wheels[w].geometry, geometry, sizeof geometry);
    }
    json_free(&root);
    return result;
}

/* ---- the file ---- */

static int header_set(swtwpm *model, char *key, char *value)
{
    int i;
    for (i = 0; i < model->n_header; ++i)
        if (!strcmp(model->keys[i], key)) {
            free(key);
            free(model->values[i]);
            model->values[i] = value;
            return 0;
        }
    if ((model->n_header & (model->n_header - 1)) == 0) {
        int capacity = model->n_header ? 2 * model->n_header : 1;
        char **keys = realloc(model->keys, (size_t)capacity * sizeof *keys);
        char **values;
        if (keys)
            model->keys = keys;
        values = keys ? realloc(model->values, (size_t)capacity * sizeof *values) : NULL;
        if (!values) {
            free(key);
            free(value);
            return SWTWPM_E_MEMORY;
        }
        model->values = values;
    }
    model->keys[model->n_header] = key;
    model->values[model->n_header++] = value;
    return 0;
}

const char *swtwpm_header(const swtwpm *model, const char *key)
{
    int i;
    for (i = 0; model && key && i < model->n_header; ++i)
        if (!strcmp(model->keys[i], key))
            return model->values[i];
    return NULL;
}

/* the column header: the number of columns of one of the accepted headers, else 0 */
static int column_count(const fields_t *f)
{
    int i;
    if (f->n != N_COLUMNS && f->n != N_COLUMNS - 3 && f->n != N_COLUMNS - 5)
        return 0;
    for (i = 0; i < f->n; ++i)
        if (strcmp(f->field[i], COLUMNS[i]))
            return 0;
    return f->n;
}

static int same_key(const wpm_row *a, const wpm_row *b)
{
    return a->quantity == b->quantity && a->multipass == b->multipass
           && a->load_n == b->load_n && !strcmp(a->soil, b->soil) && !strcmp(a->wheel, b->wheel);
}

/* one comment line before the column header (parse_wpm_csv) */
static int header_line(swtwpm *model, const char *line, const char *end, const context_t *ctx,
                       int *geometry_line)
{
    const char *colon = memchr(line, ':', (size_t)(end - line));
    char *key, *value;
    int first = model->n_header == 0, is_format;
    if (!colon)
        return problem(ctx, "header comment must read '# key: value'");
    key = strip_copy(line + 1, colon);
    value = strip_copy(colon + 1, end);
    if (!key || !value) {
        free(key);
        free(value);
        return SWTWPM_E_MEMORY;
    }
    is_format = !strcmp(key, "format");
    if (!strcmp(key, "wheel_geometry"))
        *geometry_line = ctx->line;
    TRY(header_set(model, key, value));
    if (first && !is_format)
        return problem(ctx, "first line must be '# format: " SWTWPM_FORMAT "'");
    return 0;
}

static int read_rows(swtwpm *model, const char *text, size_t size, context_t *ctx)
{
    const unsigned char *s = (const unsigned char *)text, *end = s + size;
    int columns = 0, columns_line = 0, geometry_line = 0, capacity = 0, result = 0;
    fields_t f = {0, 0, NULL};
    size_t bad;
    if (size >= 3 && s[0] == 0xEF && s[1] == 0xBB && s[2] == 0xBF)
        s += 3;
    bad = utf8_invalid_at(s, (size_t)(end - s));
    if (bad < (size_t)(end - s)) {
        const unsigned char *c;
        ctx->line = 1;
        for (c = (const unsigned char *)text; c < s + bad; ++c)
            ctx->line += *c == '\n';
        return problem(ctx, "not UTF-8");
    }
    if (memchr(s, '\0', (size_t)(end - s))) {
        const unsigned char *c;
        ctx->line = 1;
        for (c = s; *c; ++c)
            ctx->line += *c == '\n';
        return problem(ctx, "line contains NUL");
    }
    ctx->line = 0;
    while (s < end && !result) {
        const unsigned char *line = s, *stop = s, *b;
        size_t n;
        while (stop < end && !line_break(stop, end))
            ++stop;
        s = stop + line_break(stop, end);
        ++ctx->line;
        for (b = line; b < stop && (n = space_at(b, stop)); b += n)
            ;
        if (b == stop)
            continue; /* empty line */
        if (!columns_line) {
            const char *format;
            if (*line == '#') {
                result = header_line(model, (const char *)line, (const char *)stop, ctx,
                                     &geometry_line);
                continue;
            }
            format = swtwpm_header(model, "format");
            if (!format || strcmp(format, SWTWPM_FORMAT)) {
                result = format ? problem(ctx, "format '%s', this reader reads '" SWTWPM_FORMAT
                                          "'", format)
                                : problem(ctx, "missing '# format: " SWTWPM_FORMAT "' line "
                                          "before the column header");
                break;
            }
            if (!split_csv((const char *)line, (const char *)stop, &f)) {
                result = SWTWPM_E_MEMORY;
                break;
            }
            columns = column_count(&f);
            fields_free(&f);
            if (!columns) {
                result = problem(ctx, "column header must be soil,wheel,multipass,load_n,"
                                 "quantity,unit,degree,slip_min,slip_max,a0,a1,a2,a3,a4,a5,a6,"
                                 "a7,n_points,rmse,step_below_zero,slope_below_zero,k95,"
                                 "scatter_sd,covariance (or without k95, scatter_sd, "
                                 "covariance, or without those and step_below_zero, "
                                 "slope_below_zero)");
                break;
            }
            columns_line = ctx->line;
            continue;
        }
        if (model->n_rows == capacity) {
            int grown_capacity = capacity ? 2 * capacity : 16;
            wpm_row *grown = realloc(model->rows, (size_t)grown_capacity * sizeof *grown);
            if (!grown) {
                result = SWTWPM_E_MEMORY;
                break;
            }
            model->rows = grown;
            capacity = grown_capacity;
        }
        if (!split_csv((const char *)line, (const char *)stop, &f)) {
            result = SWTWPM_E_MEMORY;
            break;
        }
        result = parse_row(ctx, &f, columns, &model->rows[model->n_rows]);
        fields_free(&f);
        if (!result) {
            wpm_row *row = &model->rows[model->n_rows++];
            int i;
            for (i = 0; i < model->n_rows - 1; ++i)
                if (same_key(&model->rows[i], row)) {
                    char load[40];
                    wpm_repr(row->load_n, load);
                    result = problem(ctx, "duplicate curve ('%s', '%s', %lld, %s, '%s') (also "
                                     "line %d)", row->soil, row->wheel, row->multipass, load,
                                     QUANTITY_NAMES[row->quantity], model->rows[i].line);
                    break;
                }
        } else { /* a half-read row: free what it holds */
            free(model->rows[model->n_rows].soil);
            free(model->rows[model->n_rows].wheel);
        }
    }
    if (result)
        return result;
    if (!columns_line) {
        ctx->line = 0;
        return model->n_header ? problem(ctx, "no column header")
                               : problem(ctx, "empty file: no '# format: " SWTWPM_FORMAT
                                         "' line");
    }
    if (!model->n_rows) {
        ctx->line = columns_line;
        return problem(ctx, "no curve rows after the column header");
    }
    ctx->line = geometry_line;
    if (swtwpm_header(model, "wheel_geometry")) {
        int i, w;
        char lacking[512] = "";
        TRY(wheel_geometry(model, swtwpm_header(model, "wheel_geometry"), ctx));
        if (!model->n_wheels)
            return 0;
        for (i = 0; i < model->n_rows; ++i) { /* sorted, once each, as Python's sorted(set) */
            const char *name = model->rows[i].wheel;
            int listed = 0, j;
            for (w = 0; w < model->n_wheels && strcmp(model->wheels[w].name, name); ++w)
                ;
            for (j = 0; j < i && !listed; ++j)
                listed = !strcmp(model->rows[j].wheel, name);
            if (w == model->n_wheels && !listed && strlen(lacking) + strlen(name) + 6
                < sizeof lacking) {
                strcat(lacking, *lacking ? ", '" : "'");
                strcat(lacking, name);
                strcat(lacking, "'");
            }
        }
        if (*lacking)
            return problem(ctx, "wheel_geometry lacks wheel(s) [%s] of the curves", lacking);
    }
    return 0;
}

int swtwpm_parse(const char *text, size_t size, const char *name, swtwpm **out, char *msg,
                 size_t msg_size)
{
    swtwpm *model;
    context_t ctx;
    int result;
    if (msg && msg_size)
        msg[0] = '\0';
    if (!out || (!text && size)) {
        wpm_message(msg, msg_size, "swtwpm_parse: NULL argument");
        return SWTWPM_E_ARGUMENT;
    }
    *out = NULL;
    model = calloc(1, sizeof *model);
    if (!model || !(model->name = duplicate(name ? name : "<text>"))) {
        free(model);
        wpm_message(msg, msg_size, "out of memory");
        return SWTWPM_E_MEMORY;
    }
    ctx.name = model->name;
    ctx.line = 0;
    ctx.msg = msg;
    ctx.msg_size = msg_size;
    result = read_rows(model, text ? text : "", size, &ctx);
    if (!result)
        result = wpm_build_sets(model, msg, msg_size);
    if (result == SWTWPM_E_MEMORY)
        wpm_message(msg, msg_size, "%s: out of memory", model->name);
    if (result) {
        swtwpm_free(model);
        return result;
    }
    *out = model;
    return 0;
}

int swtwpm_open(const char *path, swtwpm **out, char *msg, size_t msg_size)
{
    FILE *file;
    char *text = NULL;
    size_t size = 0, capacity = 0;
    int result;
    if (!path || !out) {
        wpm_message(msg, msg_size, "swtwpm_open: NULL argument");
        return SWTWPM_E_ARGUMENT;
    }
    *out = NULL;
    file = fopen(path, "rb");
    if (!file) {
        wpm_message(msg, msg_size, "%s: cannot open: %s", path, strerror(errno));
        return SWTWPM_E_IO;
    }
    for (;;) {
        size_t got;
        if (size == capacity) {
            char *grown;
            capacity = capacity ? 2 * capacity : 65536;
            grown = realloc(text, capacity);
            if (!grown) {
                free(text);
                fclose(file);
                wpm_message(msg, msg_size, "%s: out of memory", path);
                return SWTWPM_E_MEMORY;
            }
            text = grown;
        }
        got = fread(text + size, 1, capacity - size, file);
        size += got;
        if (got == 0)
            break;
    }
    if (ferror(file)) {
        free(text);
        fclose(file);
        wpm_message(msg, msg_size, "%s: read error", path);
        return SWTWPM_E_IO;
    }
    fclose(file);
    result = swtwpm_parse(text, size, path, out, msg, msg_size);
    free(text);
    return result;
}

void swtwpm_free(swtwpm *model)
{
    int i;
    if (!model)
        return;
    wpm_free_sets(model);
    for (i = 0; i < model->n_rows; ++i) {
        free(model->rows[i].soil);
        free(model->rows[i].wheel);
    }
    free(model->rows);
    for (i = 0; i < model->n_header; ++i) {
        free(model->keys[i]);
        free(model->values[i]);
    }
    free(model->keys);
    free(model->values);
    for (i = 0; i < model->n_wheels; ++i)
        free(model->wheels[i].name);
    free(model->wheels);
    free(model->name);
    free(model);
}
