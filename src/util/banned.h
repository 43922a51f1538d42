/*
 * Functions banned from src/ (STYLE.md section 11, after git's banned.h):
 * unbounded string copies and strtok's hidden state. Use snprintf/memcpy.
 */
#ifndef ASP_UTIL_BANNED_H
#define ASP_UTIL_BANNED_H

#define ASP_BANNED(func) sorry_##func##_is_a_banned_function

#undef strcpy
#define strcpy(x, y) ASP_BANNED(strcpy)
#undef strcat
#define strcat(x, y) ASP_BANNED(strcat)
#undef sprintf
#define sprintf(...) ASP_BANNED(sprintf)
#undef vsprintf
#define vsprintf(...) ASP_BANNED(vsprintf)
#undef strtok
#define strtok(x, y) ASP_BANNED(strtok)

#endif
