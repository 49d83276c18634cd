/* Generates cfmt_cases.tsv: glibc printf output for demx's cfmt tests.
   gcc cfmt_gen.c -o /tmp/cfmt_gen && /tmp/cfmt_gen > cfmt_cases.tsv
   Columns: format, f (float) or d (integer), argument (%a hex float or decimal), output in [brackets]. */
#include <stdio.h>
#include <math.h>
int main(void) {
  const char *ff[] = {"%g","%G","%e","%E","%f","%F","%.3g","%.0g","%.1g","%.10g","%.15g","%.16g","%.17g","%20.15g","%-20.15g|",
    "%-1.16e","%.0e","%.0f","%.2f","%#g","%#.3g","%#.0f","%#.0e","%+g","% g","%010.3f","%-10.3e|","%+012.4E","%12g","%012g",
    "%.3e","%.8f","%.12g","%10.4f","%15.8e","%.20f","%.30g"};
  double vals[] = {0.0,-0.0,1.0,-1.0,0.5,1.5,2.5,-2.5,0.125,0.375,0.0005,0.00015,9.9995,99.995,0.1,0.2,1.0/3.0,2.0/3.0,
    123456.0,1234567.0,999999.5,9999995.0,1e-4,1e-5,0.000123456789,1e-300,1e300,-1e300,5e-324,1.7976931348623157e308,
    2.2250738585072014e-308,3.14159265358979,-2.718281828459045,1e15,1e16,1e17,1e21,1e22,1e23,6.02214076e23,
    0.0837758041,-1.02596e-17,4.0000000000000001e-02,INFINITY,-INFINITY,NAN,-NAN,
    123.456,0.95,0.05,0.45,1.005,2.675,1e-7,12345678901234567890.0};
  const char *df[] = {"%d","%i","%5d","%-5d|","%05d","%+d","% d","%.3d","%.0d","%8.3d","%-+6d|","%ld","%lld","%u","%lu","%x","%X","%#x","%o","%#o","%10ld","%-010d|"};
  long long ivals[] = {0,1,-1,7,42,-42,100,-100,123456,-123456,2147483647,-2147483647LL-1,9007199254740993LL,-9007199254740993LL,255,4096};
  for (unsigned i = 0; i < sizeof ff / sizeof *ff; i++)
    for (unsigned j = 0; j < sizeof vals / sizeof *vals; j++) {
      printf("%s\tf\t%a\t[", ff[i], vals[j]);
      printf(ff[i], vals[j]);
      printf("]\n");
    }
  for (unsigned i = 0; i < sizeof df / sizeof *df; i++)
    for (unsigned j = 0; j < sizeof ivals / sizeof *ivals; j++) {
      const char *f = df[i];
      int isl = 0; for (const char *p = f; *p; p++) if (*p == 'l') isl = 1;
      printf("%s\td\t%lld\t[", f, ivals[j]);
      if (isl) printf(f, (long long)ivals[j]); else printf(f, (int)ivals[j]);
      printf("]\n");
    }
  return 0;
}
