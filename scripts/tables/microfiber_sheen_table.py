#!/usr/bin/env python3
"""The Charlie sheen lobe's directional albedo (Charlie distribution with
Neubelt-Pettineo visibility; kernels/closures/mp_bsdf.h, mp_charlie_sheen_table,
which stands in for the velvet lobe's albedo) by quadrature over the
hemisphere, on a 9 x 9 grid: rows of view cosine 0.02, 0.125 .. 1, columns
of roughness 0.05, 0.125 .. 1. Prints the table and its initialiser."""
import numpy as np
def charlie(nh, a):
    inv = 1/a; s = np.sqrt(np.maximum(1-nh*nh,0))
    return (2+inv)*s**inv/(2*np.pi)
def vis(nl,nv): return 1/(4*(nl+nv-nl*nv))
N=400
th=(np.arange(N)+0.5)/N*np.pi/2; ph=(np.arange(2*N)+0.5)/(2*N)*2*np.pi
T,P=np.meshgrid(th,ph,indexing='ij'); dw=(np.pi/2/N)*(2*np.pi/(2*N))*np.sin(T)
L=np.stack([np.sin(T)*np.cos(P),np.sin(T)*np.sin(P),np.cos(T)],-1)
nvs=np.linspace(0,1,9); nvs[0]=0.02; rs=np.linspace(0,1,9); rs[0]=0.05
tab=np.zeros((9,9))
for i,nv in enumerate(nvs):
    V=np.array([np.sqrt(1-nv*nv),0,nv])
    H=L+V; H/=np.linalg.norm(H,axis=-1,keepdims=True)
    for j,r in enumerate(rs):
        a=max(r*r,1e-3)
        f=charlie(H[...,2],a)*vis(L[...,2],nv)
        tab[i,j]=(f*L[...,2]*dw).sum()
np.set_printoptions(precision=4,suppress=True)
print(tab)
print(",".join(f"{x:.4f}f" for x in tab.flatten()))
